// Strict uniform patch usage (LazyFluids, thesis §5.4.1-5.4.2): reversed
// retrieval with counters, so every source patch is used K or K+1 times per
// segment label.
#include <algorithm>

#include "tempera/error.hpp"
#include "tempera/patch_usage.hpp"
#include "tempera/reversed_retrieval.hpp"
#include "tempera/synthesis_options.hpp"

namespace tempera {

UsageStats retrieve_uniform(const PatchSpace& space, const SearchConstraints& cons, OffsetField& nnf,
                                        const ReversedRetrievalParams& params, std::uint64_t stream) {
  const int sw = space.source->width;
  ReversedRetrieval rr(space, cons, nnf, params, stream);
  // Per segment: K = |X_s| / |Z_s| uses for every source, R of them once more.
  const std::size_t segments = cons.valid_by_segment.size();
  std::vector<std::size_t> targets(segments, 0), quota(segments, 0), extra(segments, 0);
  for (std::size_t q = 0; q < cons.target_active.size(); ++q)
    if (cons.target_active[q]) ++targets[cons.segment_of_target(q)];
  for (std::size_t s = 0; s < segments; ++s) {
    const std::size_t z = cons.valid_by_segment[s].size();
    if (z == 0) continue;
    quota[s] = targets[s] / z;
    extra[s] = targets[s] % z;
  }
  std::vector<std::uint32_t> uses(std::size_t(sw) * space.source->height, 0);
  auto can_take = [&](std::size_t p) {
    const int s = cons.segment_of_source(p);
    return uses[p] < quota[s] || (uses[p] == quota[s] && extra[s] > 0);
  };
  auto take = [&](const Assignment& a) {
    const int s = cons.segment_of_source(a.source);
    if (uses[a.source] == quota[s]) --extra[s];
    ++uses[a.source];
    rr.assign(a);
  };
  auto refresh_eligible = [&] {
    for (std::size_t p = 0; p < uses.size(); ++p) rr.eligible()[p] = cons.source_valid[p] && can_take(p);
  };
  UsageStats stats;
  const int max_rounds = 64;  // then a greedy fill finishes the last few
  while (rr.assigned_count() < rr.active() && stats.rounds < max_rounds) {
    refresh_eligible();
    auto winners = rr.round(stats.rounds++);
    std::sort(winners.begin(), winners.end());  // best first: counters fill with the best pairs
    std::size_t taken = 0;
    for (const auto& a : winners)
      if (can_take(a.source)) take(a), ++taken;
    if (taken == 0) break;
  }
  stats.covered = double(rr.assigned_count()) / double(std::max<std::size_t>(1, rr.active()));
  // Greedy fill: each remaining target takes the best of a deterministic sample
  // of sources that still have capacity (its forward match first).
  if (rr.assigned_count() < rr.active()) {
    refresh_eligible();
    std::vector<std::vector<std::int32_t>> open(segments);
    for (std::size_t p = 0; p < uses.size(); ++p)
      if (rr.eligible()[p]) open[cons.segment_of_source(p)].push_back(std::int32_t(p));
    std::vector<std::uint8_t> pruned(segments, 0);
    Rng rng(params.seed, mix64(stream) ^ 0xF111ull);
    for (std::size_t q = 0; q < cons.target_active.size(); ++q) {
      if (!cons.target_active[q] || rr.is_assigned(q)) continue;
      auto& pool = open[cons.segment_of_target(q)];
      const int tx = int(q % nnf.width), ty = int(q / nnf.width);
      std::size_t best_slot = pool.size();
      float best = kNoDistance;
      for (int k = 0; k < 33 && !pool.empty(); ++k) {
        const std::size_t slot = rng.below(int(pool.size()));
        const std::int32_t p = pool[slot];
        const float d = patch_distance(space, p % sw, p / sw, tx, ty, best);
        if (d < best) best = d, best_slot = slot;
      }
      if (best_slot == pool.size()) throw ValueError("internal: uniform retrieval ran out of source capacity");
      const std::int32_t p = pool[best_slot];
      take({best, std::int32_t(q), p});
      if (!can_take(p)) pool[best_slot] = pool.back(), pool.pop_back();
      // When the last extra use of a segment is spent, sources at K are full.
      const int s = cons.segment_of_source(p);
      if (extra[s] == 0 && !pruned[s]++)
        pool.erase(std::remove_if(pool.begin(), pool.end(), [&](std::int32_t o) { return !can_take(o); }),
                   pool.end());
    }
  }
  return stats;
}

namespace {

class UniformUsage final : public EnergyTerm {
 public:
  const char* name() const override { return "uniform"; }
  UsageStats reassign(const LevelContext& c, OffsetField& field, std::uint64_t stream) const override {
    ReversedRetrievalParams rr;
    rr.seed = c.seed;
    rr.threads = c.threads;
    return retrieve_uniform(*c.space, *c.constraints, field, rr, stream);
  }
};

}  // namespace

std::shared_ptr<const EnergyTerm> make_uniform_usage() { return std::make_shared<UniformUsage>(); }

}  // namespace tempera

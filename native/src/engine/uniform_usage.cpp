// Strict uniform patch usage (LazyFluids, thesis §5.4.1-5.4.2): reversed
// retrieval with counters, so every source patch is used K or K+1 times per
// segment label.
#include <algorithm>

#include "tempera/engine/error.hpp"
#include "tempera/engine/patch_usage.hpp"
#include "tempera/engine/reversed_retrieval.hpp"
#include "tempera/engine/synthesis_options.hpp"

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
  // Rounds until every target is assigned: each round gives every source
  // with capacity one proposal, so a quota of K needs at least K rounds and
  // no fixed cap fits every K (a cap followed by a random fill made large-K
  // assignments random). Capacity sums to the targets of each segment, so
  // while targets are open some source can take one and a round never stalls.
  while (rr.assigned_count() < rr.active()) {
    refresh_eligible();
    auto winners = rr.round(stats.rounds++);
    std::sort(winners.begin(), winners.end());  // best first: counters fill with the best pairs
    std::size_t taken = 0;
    for (const auto& a : winners)
      if (can_take(a.source)) take(a), ++taken;
    if (taken == 0) throw ValueError("internal: uniform retrieval stalled with targets left");
  }
  stats.covered = double(rr.assigned_count()) / double(std::max<std::size_t>(1, rr.active()));
  stats.wide_searches = rr.wide_searches();
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

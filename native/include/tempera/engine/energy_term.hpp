#pragma once
// Pluggable energy terms. The engine's base energy is the guided patch
// distance (patch_distance.hpp: style and guide channels, weighted); a method
// adds terms here without touching the search loop. A term may
//  - add a cost per source pixel to every match of it (usage: the occurrence
//    penalty, Bénard's thresholded histogram, a footprint count), refreshed
//    before each search;
//  - add a cost per (target, source) pair that reads the offset field
//    (Bénard's spatial coherence, eq. 5), evaluated against the field as it
//    was at the start of the PatchMatch sweep so results do not depend on the
//    thread count;
//  - reassign matches after each search (reversed retrieval: uniform usage,
//    StyLit's error budget).
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "tempera/engine/offset_field.hpp"
#include "tempera/engine/patch_distance.hpp"

namespace tempera {

struct SearchConstraints;
struct SynthesisOptions;

// What a term sees of the level being solved.
struct LevelContext {
  int level = 0;
  const PatchSpace* space = nullptr;
  const SearchConstraints* constraints = nullptr;
  const SourceLayout* layout = nullptr;
  std::uint64_t seed = 1;
  int threads = 0;
  // Per target, its source (atlas index, y * width + x) before this EM
  // iteration's search: mostly where the previous reassignment put it, a
  // seed for the next (null: none).
  const std::vector<std::int32_t>* sources_before_search = nullptr;
};

struct UsageStats {
  int rounds = 0;
  double covered = 0.0;  // fraction of active targets placed by reversed retrieval
  std::size_t wide_searches = 0;  // sources seeded at random, searched over the whole frame
};

// Sources (sx, sy) with x0 <= sx <= x1 and y0 <= sy <= y1 need a term's
// pair_cost() summed; any other costs the term `outside` (before its weight
// and limit). Bénard's coherence: sources that no neighbour's match reaches.
struct PairCostBox {
  int x0 = std::numeric_limits<int>::min(), y0 = std::numeric_limits<int>::min();
  int x1 = std::numeric_limits<int>::max(), y1 = std::numeric_limits<int>::max();
  float outside = 0.0f;
  bool contains(int sx, int sy) const { return sx >= x0 && sx <= x1 && sy >= y0 && sy <= y1; }
};

// What a term keeps across the EM iterations of one level solve (terms
// themselves are immutable and shared).
struct TermState {
  std::vector<float> values;
  int updates = 0;
};

class EnergyTerm {
 public:
  virtual ~EnergyTerm() = default;
  virtual const char* name() const = 0;
  // Adds this term's cost per source pixel into `cost` (atlas size).
  virtual void add_source_costs(const LevelContext&, const OffsetField&, std::vector<float>& /*cost*/,
                                TermState& /*state*/) const {}
  // Whether add_source_costs() is to be re-evaluated after every PatchMatch
  // iteration rather than once per search: costs held through a whole search
  // make every target leave a hotspot for the same next-best patch at once.
  virtual bool refresh_each_iteration() const { return false; }
  // Whether pair_cost() is used.
  virtual bool reads_field() const { return false; }
  // What pair_cost() of each target of row ty may reuse across that target's
  // candidates, computed once before the row is searched (the field a sweep
  // reads does not change meanwhile): boxes[tx], a box of sources outside
  // which the term's cost is one value. The default box holds every source
  // (nothing reused).
  virtual void prepare_row(const LevelContext&, const OffsetField&, int /*ty*/, PairCostBox* /*boxes*/) const {}
  // Extra cost of matching target (tx, ty) to source (sx, sy), given the
  // field at the start of the sweep and the target's prepared box. A term may
  // stop once the cost reaches `limit` (the candidate is rejected then) and
  // return infinity instead.
  virtual float pair_cost(const LevelContext&, const OffsetField&, const PairCostBox& /*box*/, int /*tx*/,
                          int /*ty*/, int /*sx*/, int /*sy*/, float /*limit*/) const {
    return 0.0f;
  }
  // May rewrite matches after a search.
  virtual UsageStats reassign(const LevelContext&, OffsetField&, std::uint64_t /*stream*/) const { return {}; }
};

using EnergyTerms = std::vector<std::shared_ptr<const EnergyTerm>>;

// The patch-usage term the options ask for (none: nullptr). Each lives in its
// own file: occurrence_penalty.cpp, usage_histogram.cpp, uniform_usage.cpp,
// error_budget.cpp.
std::shared_ptr<const EnergyTerm> make_usage_term(const SynthesisOptions& options);

std::shared_ptr<const EnergyTerm> make_occurrence_penalty(float weight);
// Bénard et al. 2013, eq. 8: h_s * max(0, H~(p) / omega - h_tau) * d~, with H~
// the usage histogram blurred by a Gaussian of `sigma` source pixels, omega
// the fair use per source patch and d~ the median patch distance (so h_s is
// unit-free).
std::shared_ptr<const EnergyTerm> make_usage_histogram(float weight, float threshold, float sigma);
// Fluidymation's Omega: weight * d~ * (coverage of the candidate's footprint
// by the footprints in use) / fair coverage; with temporal_radius r > 0 the
// coverage of a video exemplar's pixel is averaged over r frames either side.
std::shared_ptr<const EnergyTerm> make_footprint_usage(float weight, int temporal_radius = 0);
std::shared_ptr<const EnergyTerm> make_uniform_usage();
std::shared_ptr<const EnergyTerm> make_error_budget(double coverage, int max_rounds);
// Bénard et al. 2013, eq. 5: weight * sum over the patch window of
// min(|M(p + d) - (candidate + d)|^2, r_max^2): neighbours that continue the
// candidate's offset make it cheaper.
std::shared_ptr<const EnergyTerm> make_spatial_coherence(float weight, float r_max);

}  // namespace tempera

#pragma once
// Control over how often each exemplar patch is used. Every mode is an
// EnergyTerm (energy_term.hpp), one per file:
//  - penalty (occurrence_penalty.cpp): occurrence penalty (Kaspar et al. 2015)
//    added to the matching cost;
//  - histogram (usage_histogram.cpp): Bénard et al. 2013's blurred,
//    thresholded usage histogram (eq. 8);
//  - footprint (footprint_usage.cpp): Fluidymation's Omega, usage counted
//    over patch footprints;
//  - uniform (uniform_usage.cpp): strict uniform usage by reversed NNF
//    retrieval with counters K and R per segment (LazyFluids, thesis
//    §5.4.1-5.4.2);
//  - budget (error_budget.cpp): StyLit's error budget (thesis §8.3.3).
#include <cstdint>
#include <string>
#include <vector>

#include "tempera/engine/energy_term.hpp"
#include "tempera/engine/patchmatch.hpp"
#include "tempera/engine/reversed_retrieval.hpp"
#include "tempera/engine/synthesis_options.hpp"

namespace tempera {

inline PatchUsage parse_patch_usage(const std::string& name) { return parse_enum<PatchUsage>(name, "patch usage"); }
inline const char* patch_usage_name(PatchUsage usage) { return enum_name(usage); }

// Rewrites `field` so that every valid source patch is used K or K+1 times within
// its segment (K = |X_s| / |Z_s|); `field` must hold a forward match on entry.
UsageStats retrieve_uniform(const PatchSpace& space, const SearchConstraints& constraints, OffsetField& field,
                            const ReversedRetrievalParams& params, std::uint64_t stream);

// StyLit's error-budget assignment on top of the forward match in `field`;
// `earlier_sources` (per target, a source index; may be null) seed the
// retrieval as the forward matches do.
UsageStats retrieve_with_budget(const PatchSpace& space, const SearchConstraints& constraints, OffsetField& field,
                                const ReversedRetrievalParams& params, std::uint64_t stream,
                                const std::vector<std::int32_t>* earlier_sources = nullptr);

// Knee of ascending `sorted_errors`: fits f(x) = 1 / (a - b x) to the curve in
// normalized axes and returns how many leading errors lie before f'(x) = 1.
std::size_t error_knee(const std::vector<float>& sorted_errors);
// The same from n errors' values at knee_sample_ranks(n) of their ascending
// order (an even subsample of at most 1024, the largest included; none below 8).
std::vector<std::size_t> knee_sample_ranks(std::size_t n);
std::size_t error_knee(std::size_t n, const std::vector<float>& samples);

// Occurrence penalty per source center: weight * typical distance * use / fair use.
std::vector<float> occurrence_penalty(const OffsetField& field, const SearchConstraints& constraints,
                                      int source_width, float weight);

// The scales usage costs are measured in: the median patch distance d~ of the
// active targets (at least 1e-6) and the fair use omega, active targets per
// valid source centre. valid = false when there are none.
struct UsageScale {
  float typical = 1e-6f, fair = 1.0f;
  bool valid = false;
};
UsageScale usage_scale(const OffsetField& field, const SearchConstraints& constraints);

// Uses per source center by the active targets (atlas size).
std::vector<float> usage_counts(const OffsetField& field, const SearchConstraints& constraints, int source_width);

// Fraction of valid source patches used at least once by the active targets.
double source_coverage(const OffsetField& field, const SearchConstraints& constraints, int source_width);

}  // namespace tempera

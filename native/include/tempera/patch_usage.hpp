#pragma once
// Control over how often each exemplar patch is used.
//  - penalty: occurrence penalty (Kaspar et al. 2015) added to the matching cost;
//  - uniform: strict uniform usage by reversed NNF retrieval with counters K
//    and R per segment (LazyFluids, thesis §5.4.1-5.4.2);
//  - budget: StyLit's error budget (thesis §8.3.3): repeated reversed
//    retrieval that accepts assignments only below the knee of the sorted
//    error curve, forward retrieval for what remains.
#include <cstdint>
#include <string>
#include <vector>

#include "tempera/patchmatch.hpp"

namespace tempera {

enum class PatchUsage { None, Penalty, Uniform, Budget };

PatchUsage parse_patch_usage(const std::string& name);  // ValueError for unknown names
const char* patch_usage_name(PatchUsage usage);

struct ReversedRetrievalParams {
  int pm_iterations = 1;          // PatchMatch sweeps (in source space) per round; candidates persist across rounds
  double coverage_goal = 0.95;    // budget: stop once this fraction of targets is covered
  int max_rounds = 16;            // budget: at most this many rounds
  std::uint64_t seed = 1;
  int threads = 0;
};

struct ReversedRetrievalStats {
  int rounds = 0;
  double covered = 0.0;  // fraction of active targets assigned by reversed retrieval
};

// Rewrites `nnf` so that every valid source patch is used K or K+1 times within
// its segment (K = |X_s| / |Z_s|); `nnf` must hold a forward NNF on entry.
ReversedRetrievalStats retrieve_uniform(const PatchSpace& space, const SearchConstraints& constraints, Nnf& nnf,
                                        const ReversedRetrievalParams& params, std::uint64_t stream);

// StyLit's error-budget assignment on top of the forward NNF in `nnf`.
ReversedRetrievalStats retrieve_with_budget(const PatchSpace& space, const SearchConstraints& constraints, Nnf& nnf,
                                            const ReversedRetrievalParams& params, std::uint64_t stream);

// Knee of ascending `sorted_errors`: fits f(x) = 1 / (a - b x) to the curve in
// normalized axes and returns how many leading errors lie before f'(x) = 1.
std::size_t error_knee(const std::vector<float>& sorted_errors);

// Occurrence penalty per source center: weight * typical distance * use / fair use.
std::vector<float> occurrence_penalty(const Nnf& nnf, const SearchConstraints& constraints, int source_width,
                                      float weight);

// Fraction of valid source patches used at least once by the active targets.
double source_coverage(const Nnf& nnf, const SearchConstraints& constraints, int source_width);

}  // namespace tempera

#pragma once
// The synthesis engine: guided texture optimization (EM over a coarse-to-fine
// pyramid, PatchMatch for the E-step, voting for the M-step) with selectable
// patch-usage control and rotation-aware patches. Every method in Tempera is
// this engine with its own guide layers and options.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tempera/guide_stack.hpp"
#include "tempera/patch_usage.hpp"
#include "tempera/patchmatch.hpp"

namespace tempera {

struct SynthesisOptions {
  int patch_size = 5;        // odd, >= 3
  int levels = 0;            // 0: as many as keep the coarsest side >= 4 patches
  int em_iterations = 6;     // search+vote iterations per level
  int pm_iterations = 2;     // PatchMatch sweeps per search (measured: 4 gains < 1% energy)
  PatchUsage usage = PatchUsage::Budget;
  float style_weight = 1.0f;    // weight of the A'/B' term against the guides
  float penalty_weight = 1.0f;  // lambda of the occurrence penalty
  // Fraction of the weighted guide variance kept by PCA compression of the
  // guide channels (1 = exact, no compression; off when weight maps are used).
  double guide_variance = 0.999;
  // Orientations are axial (mod pi, e.g. stroke directions) rather than
  // directed (mod 2 pi).
  bool axial_orientation = true;
  double budget_coverage = 0.95;
  int budget_max_rounds = 16;
  std::uint64_t seed = 1;
  int threads = 0;  // 0: all cores
};

struct SynthesisInput {
  ImageView style;  // A' (the exemplar), H_s x W_s x C
  GuideStack guides;
  ImageView source_mask, target_mask;                // optional, 1 channel, > 0.5 = inside
  ImageView source_orientation, target_orientation;  // optional, 1 channel, radians
  ImageView source_segments, target_segments;        // optional, 1 channel, integer labels >= 0
  // Optional, 1 channel per guide layer (or empty): per-target-pixel weight map.
  std::vector<ImageView> target_weight_maps;
  int target_width = 0, target_height = 0;  // needed only when there are no guides
};

struct LevelStats {
  int level = 0, width = 0, height = 0;
  std::vector<double> energy;  // mean patch distance after each search
  double search_seconds = 0, usage_seconds = 0, vote_seconds = 0;
  int usage_rounds = 0;
  double reversed_coverage = 0;  // fraction of targets placed by reversed retrieval (last iteration)
};

struct SynthesisResult {
  Image image;  // B'
  Nnf nnf;      // final source position per target pixel
  std::vector<LevelStats> levels;  // coarsest first
  double seconds = 0;
  double source_coverage = 0;  // fraction of source patches used at the finest level
  int guide_channels = 0;        // guide channels matched (after compression)
  double kept_guide_variance = 1;
};

// Called after every search and vote with the overall progress in [0, 1];
// returning false cancels the run (CancelledError).
using ProgressCallback = std::function<bool(double)>;

SynthesisResult synthesize(const SynthesisInput& input, const SynthesisOptions& options,
                           const ProgressCallback& progress = {});

}  // namespace tempera

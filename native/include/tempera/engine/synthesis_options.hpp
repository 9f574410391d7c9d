#pragma once
// The synthesis engine's options: the struct (with its defaults) and its
// table (names, flags, help, ranges). This is the only place they are stated;
// the CLI, the Python API and the Blender panel derive theirs from it.
#include <array>
#include <cstdint>
#include <vector>

#include "tempera/engine/option_table.hpp"

namespace tempera {

// How often each exemplar patch may be used (one implementation per file:
// occurrence_penalty, usage_histogram, uniform_usage, error_budget).
enum class PatchUsage { None, Penalty, Uniform, Budget, Histogram, Footprint };
template <>
struct EnumNames<PatchUsage> {
  static constexpr const char* what = "patch usage";
  static constexpr std::array<const char*, 6> names = {"none", "penalty", "uniform", "budget", "histogram",
                                                       "footprint"};
};

// Colour space the style channels are compared in (voting stays in the
// exemplar's own values).
enum class ColorSpace { Rgb, Lab };
template <>
struct EnumNames<ColorSpace> {
  static constexpr const char* what = "colour space";
  static constexpr std::array<const char*, 2> names = {"rgb", "lab"};
};

// How B' is made from the offset field (the M-step, and the output).
//  mean:   average of the overlapping patches' pixels (EM voting);
//  centre: each pixel copies its own source pixel, a warp and not a blend
//          (Bénard et al. 2013, §2.1);
//  mode:   the overlapping candidate closest to all the others (a weighted
//          mode; Color Me Noisy);
//  random: one overlapping candidate picked at random (Color Me Noisy).
enum class OutputMode { Mean, Centre, Mode, Random };
template <>
struct EnumNames<OutputMode> {
  static constexpr const char* what = "output mode";
  static constexpr std::array<const char*, 4> names = {"mean", "centre", "mode", "random"};
};

// Precision of the matched features. int16: 12-bit fixed point with one step
// for all channels (half the bytes per random candidate, exact integer SSD);
// int8: 8 bits (a quarter); both apply to axis-aligned, unwindowed,
// unweighted patches, the others always match in float. float: the v0.1
// results, bit for bit.
enum class FeaturePrecision { Int16, Int8, Float };
template <>
struct EnumNames<FeaturePrecision> {
  static constexpr const char* what = "feature precision";
  static constexpr std::array<const char*, 3> names = {"int16", "int8", "float"};
};

struct SynthesisOptions {
  int patch_size = 5;
  int levels = 0;
  double level_ratio = 0.5;
  std::vector<float> level_box_widths;  // per level, finest first; empty = no low-pass
  int em_iterations = 6;
  int pm_iterations = 2;  // measured: 4 gains < 1% energy
  std::vector<int> em_schedule, pm_schedule;  // per level, coarsest first
  // PatchMatch's random search below the coarsest level, from the second
  // sweep of each search on: at most this many pixels from a pixel's match
  // (the coarsest level, and each search's first sweep, reach the whole
  // exemplar: finer sweeps refine what they found). 0 = the whole exemplar
  // in every sweep, whose scales grow with its size: log2(side) candidates.
  int search_radius = 0;
  // The finest level stops its EM iterations once one lowers the energy by
  // less than this fraction (0: all of them). Measured on ebsynth's StyLit
  // still (docs/benchmarks.md, issue 32 step 21).
  double em_tolerance = 0.02;
  bool skip_converged = true;  // converged_pixels.hpp; finest level only, within 2% of the full search
  PatchUsage usage = PatchUsage::Budget;
  float style_weight = 1.0f;
  std::vector<float> style_channel_weights;  // empty = 1 for every style channel
  ColorSpace color_space = ColorSpace::Rgb;
  float window_sigma = 0.0f;
  OutputMode output = OutputMode::Mean;
  float penalty_weight = 1.0f;  // also the weight of the footprint term
  float histogram_weight = 1.0f;
  float histogram_threshold = 2.0f;
  float histogram_sigma = 1.5f;
  double guide_variance = 0.999;
  FeaturePrecision feature_precision = FeaturePrecision::Int16;
  // Per-pixel target weights (SynthesisInput::target_weight_maps) keep the
  // fixed-point features, patches that meet a weighted pixel corrected one by
  // one (patch_distance.hpp); false: such levels match in float, as before.
  // A method opts in once measured (issue 32: StyLit's temporal guide, 1.5x
  // faster, energy within 1%); not a command-line option.
  bool fixed_point_weights = false;
  bool axial_orientation = true;
  double budget_coverage = 0.95;
  int budget_max_rounds = 16;
  std::uint64_t seed = 1;
  int threads = 0;
};

inline const auto& synthesis_option_table() {
  using S = SynthesisOptions;
  static const auto table = std::make_tuple(
      field(&S::patch_size, "patch_size", "patch-size",
            "odd patch width in pixels: 5 typical, 7-9 keep larger strokes, 3 follows the guides closely", 3, 31),
      field(&S::levels, "levels", "levels", "pyramid levels, 0 = as many as keep the coarsest side >= 4 patches",
            0, 16),
      field(&S::level_ratio, "level_ratio", "level-ratio",
            "size ratio between pyramid levels: 0.5 typical, 0.85 for Color Me Noisy", 0.25, 0.95),
      field(&S::level_box_widths, "level_box_widths", "level-box-widths",
            "box low-pass width in pixels per level, finest first (Color Me Noisy's h_f); empty = none", 0, 1000),
      field(&S::em_iterations, "em_iterations", "em-iters", "search+vote iterations per level (6 typical)", 1,
            1000),
      field(&S::pm_iterations, "pm_iterations", "pm-iters", "PatchMatch sweeps per search (2 typical)", 0, 1000),
      field(&S::em_schedule, "em_schedule", "em-schedule",
            "EM iterations per level, coarsest first; levels past the list use em_iterations", 1, 1000),
      field(&S::pm_schedule, "pm_schedule", "pm-schedule",
            "PatchMatch sweeps per level, coarsest first; levels past the list use pm_iterations", 0, 1000),
      field(&S::search_radius, "search_radius", "search-radius",
            "random search below the coarsest level, after each search's first sweep: at most this many pixels "
            "from a pixel's match (the coarsest level and first sweeps reach the whole exemplar); 0 = the whole "
            "exemplar in every sweep",
            0, 1e6),
      field(&S::em_tolerance, "em_tolerance", "em-tolerance",
            "the finest level stops iterating once an EM iteration lowers the energy by less than this fraction: "
            "0.02 stops ebsynth's StyLit still after 4 of 6, 0.7x the time, judged energy +0.4%; "
            "0 runs every iteration",
            0, 1),
      field(&S::skip_converged, "skip_converged", "skip-converged",
            "the forward search skips pixels whose match, neighbours' matches and patch of B' did not change in "
            "the last EM iteration, at the finest level only: about 50% fewer searches there at 1 Mpix, about 0.9x the "
            "time, quality within 2% of the full search; false searches every pixel every time"),
      field(&S::usage, "usage", "usage",
            "patch usage: budget (StyLit, no wash-out), uniform (every patch equally), penalty, histogram and "
            "footprint (overused patches cost more), none (fastest)"),
      field(&S::style_weight, "style_weight", "style-weight",
            "weight of the style term (A'/B') against the guides; 1 typical", 0, 1e6),
      field(&S::style_channel_weights, "style_channel_weights", "style-channel-weights",
            "weight per style channel, e.g. 1,1,1,3 weighs alpha 3x (LazyFluids); empty = all 1", 0, 1e6),
      field(&S::color_space, "color_space", "color-space",
            "colour space of style matching: rgb, or lab where regions differ in hue but not in RGB distance"),
      field(&S::window_sigma, "window_sigma", "window-sigma",
            "Gaussian weighting of patch pixels (sigma in pixels, 3 for Benard's 9x9 window); 0 = uniform", 0,
            100),
      field(&S::output, "output", "output-mode",
            "how B' is made: mean (blend of patches), centre (warp, no blending), mode or random (noisy)"),
      field(&S::penalty_weight, "penalty_weight", "penalty-weight",
            "lambda of the occurrence penalty and of the footprint term: 1 typical, higher spreads patches more", 0,
            1e6),
      field(&S::histogram_weight, "histogram_weight", "histogram-weight",
            "h_s of the histogram term (usage histogram): cost per use above the threshold, 1 typical", 0, 1e6),
      field(&S::histogram_threshold, "histogram_threshold", "histogram-threshold",
            "h_tau of the histogram term, in multiples of the fair use per patch; 2 typical", 0, 1e6),
      field(&S::histogram_sigma, "histogram_sigma", "histogram-sigma",
            "Gaussian blur of the usage histogram, in source pixels; 1.5 typical", 0, 100),
      field(&S::guide_variance, "guide_variance", "guide-variance",
            "guide variance kept by PCA compression of the guide channels; 1 = exact (slower)", 1e-6, 1),
      field(&S::feature_precision, "feature_precision", "feature-precision",
            "features matched as int16 (12-bit fixed point), int8 (8-bit: least memory traffic) or float (exact, slowest)"),
      field(&S::axial_orientation, "axial_orientation", "axial-orientation",
            "orientations are axial (mod pi, like strokes) rather than directed (mod 2 pi)"),
      field(&S::budget_coverage, "budget_coverage", "budget-coverage",
            "error budget: stop reversed retrieval once this fraction of the frame is covered", 1e-6, 1),
      field(&S::budget_max_rounds, "budget_max_rounds", "budget-max-rounds",
            "error budget: at most this many reversed-retrieval rounds per iteration", 1, 1000),
      field(&S::seed, "seed", "seed", "random seed: the same seed and inputs give the same result", 0,
            1.8446744073709552e19),
      not_in_settings(field(&S::threads, "threads", "threads",
                            "worker threads, 0 = all cores (results do not depend on it)", 0, 4096)));
  return table;
}

// Range checks of the table plus the rules that tie options together.
void validate(const SynthesisOptions& options);

}  // namespace tempera

#pragma once
// Stylizing Animation by Example (Bénard et al. 2013, "TCIA") as a method on
// the engine: a whole shot solved coarse to fine, with at each level one
// forward and one backward sweep through time (§3.3, Fig. 7). Each frame's
// offset field M_t starts from the advected field of the frame before (in
// sweep order) randomly merged, per pixel, with the frame's own previous
// solution (the coarser level's, upsampled, or the forward sweep's), taking
// the unoccluded one where χ says so. Each visit runs PatchMatch on the
// frame with
//  - the input term (guides of the frame against the exemplar's, eq. 4) and
//    the output term (B' against Ŝ, eq. 3) of the engine, in a Gaussian
//    window (eq. 1, 9 x 9, sigma 3);
//  - the temporal term g_tc (eq. 6, 7): the previous frame's result advected
//    along V- (forward) or V+ (backward) as a guide paired with Ŝ, weighted
//    by χ- or χ+;
//  - spatial coherence (eq. 5) and the usage histogram (eq. 8);
// and "warps, not blends": each pixel copies its source pixel (output
// centre). Painted keys (§4.1) are hard constraints and extra exemplars, and
// the random merge leans toward the nearer key. Ribbons (tcia_ribbons.hpp) give
// every visit the pixels of the neighbouring keys that the motion leads to;
// eq. 10's input time-derivative term (tcia_derivative.hpp) is an option;
// orientation fields turn the patches. Layers (tcia_layers.hpp) solve each part apart.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/engine/synthesis.hpp"

namespace tempera {

struct ShotFrame {
  std::vector<ImageView> guides;                   // B_g per guide layer, in the exemplar's order
  ImageView velocity_backward, velocity_forward;   // V-, V+: 2 channels, pixels, x right, y down
  ImageView occlusion_backward, occlusion_forward; // χ-, χ+: 1 channel, 1 = visible in the neighbour frame
  // O(I_t) (§3.1), optional: 1 channel, radians, the edge direction
  // (engine/orientation.hpp): the tensor's angle or the artist's AOV. With the
  // style's orientation too, patches are compared rotated by the smallest
  // angle between the two, so hatching follows the frame's field.
  ImageView orientation;
};

// A painted keyframe (§4.1): the frame's painting, optionally only where
// `mask` > 0.5 (a partial key). It is a hard constraint at its frame and an
// extra exemplar (with the frame's guides) for every frame.
struct ShotKey {
  int frame = 0;       // index into Shot::frames
  ImageView painting;  // the frame's size, the style's channels
  ImageView mask;      // optional, 1 channel
};

struct Shot {
  ImageView style;                      // Ŝ
  ImageView style_mask;                 // optional, 1 channel: > 0.5 = where matches in Ŝ may come from (a layer's part)
  std::vector<std::string> guide_names;
  std::vector<ImageView> style_guides;  // S per guide layer
  std::vector<float> guide_weights;     // w_in per guide layer
  ImageView style_orientation;          // O(S), optional (see ShotFrame::orientation)
  std::vector<ShotFrame> frames;
  std::vector<ShotKey> keys;            // in frame order
};

struct TciaOptions {
  // w_tc. The paper gives none; 3 is the smallest that keeps every frame of
  // a 10-frame shot within 1.2x of per-frame patch statistics and the last
  // third's flicker at the first's (tests/cpp/test_tcia.cpp; 1 let the
  // shot's last frames wash out).
  float temporal_weight = 3.0f;
  float coherence_weight = 0.05f;  // w_sc per window pixel: "small" (§3.2)
  float coherence_max = 3.0f;      // r_max in pixels (the paper gives none)
  int sweep_pairs = 1;             // forward + backward sweeps per level (the paper: 1)
  // Ribbons (§4.1): each pixel's surface point in the previous and next key,
  // followed along the motion, tried as PatchMatch candidates at every visit.
  bool ribbons = true;
  // w_∂in of eq. 10 (tcia_derivative.hpp), times each guide's weight, with
  // keys only: the in-betweens change the way the input does.
  float derivative_weight = 0.0f;
  SynthesisOptions synthesis;      // tcia_defaults()
};

inline const auto& tcia_option_table() {
  using T = TciaOptions;
  static const auto table = std::make_tuple(
      field(&T::temporal_weight, "temporal_weight", "temporal",
            "w_tc: pull towards the neighbour frame's paint along the motion; 3 typical", 0, 1e6),
      field(&T::coherence_weight, "coherence_weight", "coherence",
            "w_sc: preference for large coherent pieces of the exemplar; 0.05 typical", 0, 1e6),
      field(&T::coherence_max, "coherence_max", "coherence-max", "r_max of spatial coherence, in pixels (3)", 0,
            1e6),
      field(&T::sweep_pairs, "sweep_pairs", "sweeps", "forward+backward sweep pairs per level (1)", 1, 100),
      field(&T::ribbons, "ribbons", "ribbons",
            "try each pixel's surface point in the previous and next key, followed along the motion (on)"),
      field(&T::derivative_weight, "derivative_weight", "derivative",
            "w_din (eq. 10), with keys: in-betweens change as the input does, times each guide's weight; 0 = off (see coherent.md)",
            0, 1e6));
  return table;
}

// The engine options of the method: 9 x 9 patches in a Gaussian window of
// sigma 3, output centre (a warp), usage histogram, automatic levels (coarsest side >= 4 patches), one search of
// 4 PatchMatch iterations per visit, exact guides.
SynthesisOptions tcia_defaults();
inline TciaOptions default_tcia_options() {
  TciaOptions o;
  o.synthesis = tcia_defaults();
  return o;
}

// `image` at width x height by nearest pick (velocities: no blending across
// motion boundaries), values scaled by `scale`.
Image pick_resize(const ImageView& image, int width, int height, float scale = 1.0f);

// The stylized frames of the shot, in order. progress(fraction) returning
// false cancels (CancelledError).
std::vector<Image> stylize_shot(const Shot& shot, const TciaOptions& options, const ProgressCallback& progress = {});

// Where the sweeps are, reported after each frame visit: level counts down
// from levels - 1 (coarsest) to 0, direction is +1 (forward sweep) or -1,
// frame is the index into Shot::frames just solved.
struct SweepProgress {
  int level = 0, levels = 0;
  int pair = 0, pairs = 0;
  int direction = +1;
  int frame = 0;
  double fraction = 0;  // of all visits of the shot
};
using SweepCallback = std::function<bool(const SweepProgress&)>;

// stylize_shot with the sweep position in the progress (the CLI's and the
// panel's progress lines); returning false cancels (CancelledError).
std::vector<Image> stylize_shot_sweeps(const Shot& shot, const TciaOptions& options, const SweepCallback& progress);

}  // namespace tempera

#pragma once
// LazyFluids (Jamriška et al. 2015; thesis ch. 5) as a method on the engine:
// an RGBA exemplar of a fluid element (smoke, fire, ink) is carried along a
// target flow inside a target alpha mask, frame after frame. Per frame t
// (frame 1 with λ = 0, then forward):
//  - the target alpha X_a^t and the exemplar alpha Z_a are blurred,
//    α = G_r(a), and split into boundary and interior (alpha_segments.hpp);
//    pixels with α <= l are not synthesized and come out transparent;
//  - the previous output is advected along the flow, X̂^{t-1}(p) =
//    X^{t-1}(p - F^{t-1}(p)) (transparent from outside the frame);
//  - the distance of eq. 5.9 is the engine's: the RGBA style with channel
//    weights 1,1,1,3, a guide layer of the blurred alphas weighted η, and a
//    guide layer pairing the exemplar z^{t-1} with X̂^{t-1} (alpha scaled by
//    √3, so its squared difference weighs 3) weighted per pixel by λ_q
//    (eq. 5.6);
//  - strict uniform usage per segment (uniform_usage.cpp): every exemplar
//    patch of a segment is used K or K+1 times, so the exemplar's texture
//    never washes out however long the sequence runs.
// Options: the exemplar also pre-rotated by 90/180/270° (more sources for
// turning flows), a motion blur of the output along the flow, and the warm
// start (on by default: the finest level only, from the previous frame's
// field advected; pixels the advected output leaves empty start afresh).
#include <vector>

#include "tempera/methods/lazyfluids/alpha_segments.hpp"
#include "tempera/engine/image.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/engine/synthesis.hpp"

namespace tempera {

struct LazyFluidsOptions {
  float temporal_weight = 0.2f;  // λ of eq. 5.6
  float alpha_guide_weight = 3;  // η: weight of the blurred-alpha guide
  float alpha_weight = 3;        // weight of the alpha channel against RGB (style and temporal term)
  float alpha_radius = 3;        // r of G_r, pixels
  float alpha_lower = 0.1f;      // l
  float alpha_upper = 0.9f;      // u
  bool rotations = false;        // the exemplar also rotated by 90, 180 and 270 degrees
  float motion_blur = 0;         // streak length along the flow, pixels (0 = off)
  bool warm_start = true;        // with λ > 0: finest level only, from the previous frame's matches advected
  SynthesisOptions synthesis;    // lazyfluids_defaults()
};

inline const auto& lazyfluids_option_table() {
  using L = LazyFluidsOptions;
  static const auto table = std::make_tuple(
      field(&L::temporal_weight, "temporal_weight", "lambda",
            "lambda: pull towards the previous frame advected along the flow (temporal coherence); 0.2 typical",
            0, 1e6),
      field(&L::alpha_guide_weight, "alpha_guide_weight", "eta",
            "eta: weight of the blurred-alpha guide (shape of the boundary); 3 typical", 0, 1e6),
      field(&L::alpha_weight, "alpha_weight", "alpha-weight",
            "weight of the alpha channel against RGB in the style and temporal terms; 3 typical", 0, 1e6),
      field(&L::alpha_radius, "alpha_radius", "alpha-radius",
            "r: Gaussian blur of the alpha masks (sigma, pixels) before segmenting; 3 typical", 0, 1000),
      field(&L::alpha_lower, "alpha_lower", "alpha-lower",
            "l: blurred alpha at or below it is outside (not synthesized, transparent); 0.1", 0, 1),
      field(&L::alpha_upper, "alpha_upper", "alpha-upper",
            "u: blurred alpha at or above it is interior, between l and u boundary; 0.9", 0, 1),
      field(&L::rotations, "rotations", "rotations",
            "also copy from the exemplar rotated by 90, 180 and 270 degrees (turning flows)"),
      field(&L::motion_blur, "motion_blur", "motion-blur",
            "motion blur of the output: streak length in pixels along the flow (0 = off)", 0, 1000),
      field(&L::warm_start, "warm_start", "warm-start",
            "frames after the first solve only the finest level, from the previous frame's matches advected along "
            "the flow (about 2.3x faster at the cold frames' energy; with lambda > 0)"));
  return table;
}

// The engine options of the method: 5 x 5 patches, strict uniform usage,
// alpha weighed 3 (style_channel_weights 1,1,1,alpha_weight), exact guides.
SynthesisOptions lazyfluids_defaults();
LazyFluidsOptions default_lazyfluids_options();

// Whether frames after the first start from the previous frame's matches:
// warm_start, and a temporal term to be coherent with (λ = 0 paints every
// frame afresh, as the artist asked).
bool warm_starts(const LazyFluidsOptions& options);

// Range checks and the rules that tie the options together (l < u).
void validate(const LazyFluidsOptions& options);

// λ_q = (1 - max(0, X_a^t(q) - X̂_a^{t-1}(q))) λ (eq. 5.6): the temporal term
// is off where material appears (emitters) and full where the advected
// previous frame already covers the target. `advected` is RGBA (alpha =
// channel 3) or 1-channel alpha.
Image temporal_weights(const ImageView& target_alpha, const ImageView& advected, float lambda);

// X̂^{t-1}: the previous output (any channels) at p - F^{t-1}(p), bilinear,
// 0 in every channel where that point lies outside the frame.
Image advect_output(const ImageView& previous_output, const ImageView& flow_previous);

// `image` rotated clockwise (x right, y down) by `quarter_turns` * 90 degrees.
Image rotate_quarter_turns(const ImageView& image, int quarter_turns);

// Line-integral convolution along the flow's streamlines: every pixel the
// mean of `image` at unit steps along F/|F| forwards and backwards, `length`
// pixels in all (a streak), where |F| > 0.01 px/frame.
Image motion_blur_along_flow(const ImageView& image, const ImageView& flow, float length);

struct FluidFrameInput {
  ImageView style;           // Z^t, RGBA
  ImageView previous_style;  // z^{t-1}, RGBA (a still exemplar: = style)
  ImageView target_alpha;    // X_a^t, 1 channel
  ImageView advected;        // X̂^{t-1}, RGBA; empty on the first frame (λ = 0)
  // With warm_start: the previous frame's final field and F^{t-1}; the
  // frame then starts from the field advected along the flow.
  const OffsetField* previous_field = nullptr;
  ImageView flow_previous;
};

struct FluidFrameResult {
  Image image;             // RGBA, transparent outside (before motion blur)
  Image temporal_weights;  // λ_q (0 everywhere on the first frame)
  Image target_labels;     // alpha_segment_labels of the target
  SynthesisResult synthesis;
};

// One frame of the sequence; progress(fraction) returning false cancels
// (CancelledError).
FluidFrameResult stylize_fluid_frame(const FluidFrameInput& input, const LazyFluidsOptions& options,
                                     const ProgressCallback& progress = {});

// The whole sequence: frame t copies from exemplar frame t mod M (a video
// exemplar of M frames loops; one frame: a still exemplar). flows[t] is F^t
// (2 channels, pixels, p moves to p + F^t in frame t + 1). Returns the
// outputs (motion-blurred when the option is on). progress gets the fraction
// of the whole sequence.
std::vector<Image> stylize_fluid_sequence(const std::vector<ImageView>& exemplar,
                                          const std::vector<ImageView>& alphas, const std::vector<ImageView>& flows,
                                          const LazyFluidsOptions& options, const ProgressCallback& progress = {});

}  // namespace tempera

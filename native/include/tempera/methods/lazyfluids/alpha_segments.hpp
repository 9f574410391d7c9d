#pragma once
// Boundary / interior segmentation of a soft alpha mask (LazyFluids, thesis
// §5.3): the alpha is blurred, α = G_r(a), and split by two opacity
// thresholds into the boundary B = {l < α < u}, the interior I = {α >= u} and
// the outside {α <= l}, which is not synthesized. Uniform patch usage is then
// enforced per segment so that boundary patches of the exemplar land only on
// the target's boundary and interior ones inside.
#include "tempera/engine/image.hpp"

namespace tempera {

struct AlphaSegmentOptions {
  float radius = 3;     // Gaussian standard deviation of G_r, pixels (0: no blur)
  float lower = 0.1f;   // l: α <= l is outside
  float upper = 0.9f;   // u: α >= u is interior
};

// Segment labels of alpha_segment_labels().
constexpr float outside_label = -1, boundary_label = 0, interior_label = 1;

// G_r(a) of a 1-channel alpha.
Image blurred_alpha(const ImageView& alpha, float radius);

// 1 channel: 0 = boundary (l < α < u), 1 = interior (α >= u), -1 = outside
// (α <= l). ValueError unless 0 <= lower < upper <= 1 and 1 channel.
Image alpha_segment_labels(const ImageView& blurred_alpha, float lower, float upper);

// A soft alpha's blurred alpha, labels and what the engine takes from them.
struct AlphaSegments {
  Image blurred;   // α
  Image labels;    // alpha_segment_labels(α)
  Image inside;    // 1 where a label >= 0 (synthesized / a valid source), else 0
  Image segments;  // the labels with outside as 0 (the engine wants labels >= 0; `inside` masks it)
};
AlphaSegments alpha_segments(const ImageView& alpha, const AlphaSegmentOptions& options);

}  // namespace tempera

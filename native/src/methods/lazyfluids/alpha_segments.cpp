#include "tempera/methods/lazyfluids/alpha_segments.hpp"

#include <algorithm>

#include "tempera/engine/error.hpp"
#include "tempera/engine/gaussian_blur.hpp"

namespace tempera {

namespace {

void require_alpha(const ImageView& alpha, const char* what) {
  require_nonempty(alpha, what);
  if (alpha.channels != 1) throw ValueError(concat(what, " must have 1 channel, got ", alpha.channels));
}

// `labels` mapped pixel by pixel through fn(label).
template <typename Fn>
Image map_labels(const Image& labels, Fn fn) {
  Image out(labels.width(), labels.height(), 1);
  const std::size_t n = labels.pixel_count();
  for (std::size_t i = 0; i < n; ++i) out.data()[i] = fn(labels.data()[i]);
  return out;
}

}  // namespace

Image blurred_alpha(const ImageView& alpha, float radius) {
  require_alpha(alpha, "alpha");
  return gaussian_blur(alpha, radius);
}

Image alpha_segment_labels(const ImageView& blurred, float lower, float upper) {
  require_alpha(blurred, "blurred alpha");
  if (!(lower >= 0 && lower < upper && upper <= 1))
    throw ValueError(concat("alpha thresholds need 0 <= lower < upper <= 1, got lower ", lower, ", upper ",
                            upper));
  Image out(blurred.width, blurred.height, 1);
  const std::size_t n = blurred.pixel_count();
  for (std::size_t i = 0; i < n; ++i) {
    const float a = blurred.data[i];
    out.data()[i] = a <= lower ? outside_label : (a >= upper ? interior_label : boundary_label);
  }
  return out;
}

AlphaSegments alpha_segments(const ImageView& alpha, const AlphaSegmentOptions& options) {
  if (!(options.radius >= 0)) throw ValueError(concat("alpha blur radius must be >= 0, got ", options.radius));
  AlphaSegments s;
  s.blurred = blurred_alpha(alpha, options.radius);
  s.labels = alpha_segment_labels(s.blurred.view(), options.lower, options.upper);
  s.inside = map_labels(s.labels, [](float l) { return l >= 0 ? 1.0f : 0.0f; });
  s.segments = map_labels(s.labels, [](float l) { return std::max(l, 0.0f); });
  return s;
}

}  // namespace tempera

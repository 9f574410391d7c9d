#include "tempera/patch_distance.hpp"

#include <algorithm>

#include "tempera/error.hpp"

namespace tempera {

FeatureImage::FeatureImage(int w, int h, int channels)
    : width(w), height(h), stride(padded(channels)), data(std::size_t(w) * h * padded(channels), 0.0f) {}

void FeatureImage::set_channels(int first, const ImageView& image, float scale) {
  if (image.width != width || image.height != height || first + image.channels > stride)
    throw ValueError("internal: feature channels do not fit the feature image");
  const std::size_t n = std::size_t(width) * height;
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < image.channels; ++c)
      data[i * stride + first + c] = image.data[i * image.channels + c] * scale;
}

void FeatureImage::set_channels(int first, const ImageView& image, const std::vector<float>& scales) {
  if (image.width != width || image.height != height || first + image.channels > stride ||
      int(scales.size()) != image.channels)
    throw ValueError("internal: feature channels do not fit the feature image");
  const std::size_t n = std::size_t(width) * height;
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < image.channels; ++c)
      data[i * stride + first + c] = image.data[i * image.channels + c] * scales[c];
}

void sample_bilinear(const float* data, int width, int height, int stride, int channels, float x,
                     float y, float* out) {
  x = std::clamp(x, 0.0f, float(width - 1));
  y = std::clamp(y, 0.0f, float(height - 1));
  const int x0 = std::min(int(x), width - 2 < 0 ? 0 : width - 2);
  const int y0 = std::min(int(y), height - 2 < 0 ? 0 : height - 2);
  const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  const float fx = x - x0, fy = y - y0;
  const float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
  const float* p00 = data + (std::size_t(y0) * width + x0) * stride;
  const float* p10 = data + (std::size_t(y0) * width + x1) * stride;
  const float* p01 = data + (std::size_t(y1) * width + x0) * stride;
  const float* p11 = data + (std::size_t(y1) * width + x1) * stride;
  for (int c = 0; c < channels; ++c) out[c] = w00 * p00[c] + w10 * p10[c] + w01 * p01[c] + w11 * p11[c];
}

namespace {

// Sum of squared differences over n floats; the simd pragma lets the compiler
// keep vector partial sums (no -ffast-math needed).
[[gnu::always_inline]] inline float ssd(const float* a, const float* b, int n) {
  float sum = 0.0f;
#pragma omp simd reduction(+ : sum)
  for (int i = 0; i < n; ++i) {
    const float d = a[i] - b[i];
    sum += d * d;
  }
  return sum;
}

[[gnu::always_inline]] inline float weighted_ssd(const float* a, const float* b, const float* w, int n) {
  float sum = 0.0f;
#pragma omp simd reduction(+ : sum)
  for (int i = 0; i < n; ++i) {
    const float d = a[i] - b[i];
    sum += w[i] * d * d;
  }
  return sum;
}

struct Window {
  int dx0, dx1, dy0, dy1;  // inclusive offsets of the target patch inside the target
};

[[gnu::always_inline]] inline Window clip(const PatchSpace& s, int tx, int ty) {
  const int r = s.radius;
  return Window{std::max(-r, -tx), std::min(r, s.target->width - 1 - tx), std::max(-r, -ty),
                std::min(r, s.target->height - 1 - ty)};
}

// Helpers are always inlined so that they are compiled into each clone of
// patch_distance (AVX2 and baseline).

// Axis-aligned patches: each patch row is one contiguous run in both images.
template <bool Weighted>
[[gnu::always_inline]] inline float distance_aligned(const PatchSpace& s, int sx, int sy, int tx, int ty, float cutoff) {
  const Window w = clip(s, tx, ty);
  const int n = (w.dx1 - w.dx0 + 1) * s.source->stride;
  float sum = 0.0f;
  for (int dy = w.dy0; dy <= w.dy1; ++dy) {
    const float* a = s.source->pixel(sx + w.dx0, sy + dy);
    const float* b = s.target->pixel(tx + w.dx0, ty + dy);
    if constexpr (Weighted)
      sum += weighted_ssd(a, b, s.target_weights->pixel(tx + w.dx0, ty + dy), n);
    else
      sum += ssd(a, b, n);
    if (sum >= cutoff) return sum;
  }
  return sum;
}

// Axis-aligned patches under a window: each pixel's SSD is weighted.
[[gnu::always_inline]] inline float distance_windowed(const PatchSpace& s, int sx, int sy, int tx, int ty,
                                                      float cutoff) {
  const Window w = clip(s, tx, ty);
  const int stride = s.source->stride, side = 2 * s.radius + 1;
  float sum = 0.0f;
  for (int dy = w.dy0; dy <= w.dy1; ++dy) {
    const float* row_w = s.window + (dy + s.radius) * side + s.radius;
    for (int dx = w.dx0; dx <= w.dx1; ++dx) {
      const float* a = s.source->pixel(sx + dx, sy + dy);
      const float* b = s.target->pixel(tx + dx, ty + dy);
      const float d = s.target_weights ? weighted_ssd(a, b, s.target_weights->pixel(tx + dx, ty + dy), stride)
                                       : ssd(a, b, stride);
      sum += row_w[dx] * d;
    }
    if (sum >= cutoff) return sum;
  }
  return sum;
}

// Rotated patches: the source is sampled bilinearly along rotated offsets.
[[gnu::always_inline]] inline float distance_rotated(const PatchSpace& s, int sx, int sy, int tx, int ty, float cutoff) {
  const Window w = clip(s, tx, ty);
  const int stride = s.source->stride;
  const float phi = s.rotation(sx, sy, tx, ty);
  const float c = std::cos(phi), sn = std::sin(phi);
  const int side = 2 * s.radius + 1;
  float sample[256];
  float sum = 0.0f;
  for (int dy = w.dy0; dy <= w.dy1; ++dy) {
    for (int dx = w.dx0; dx <= w.dx1; ++dx) {
      const float weight = s.window ? s.window[(dy + s.radius) * side + dx + s.radius] : 1.0f;
      const float x = sx + c * dx - sn * dy, y = sy + sn * dx + c * dy;
      sample_bilinear(s.source->data.data(), s.source->width, s.source->height, stride, stride, x, y,
                      sample);
      const float* b = s.target->pixel(tx + dx, ty + dy);
      sum += weight * (s.target_weights ? weighted_ssd(sample, b, s.target_weights->pixel(tx + dx, ty + dy), stride)
                                        : ssd(sample, b, stride));
    }
    if (sum >= cutoff) return sum;
  }
  return sum;
}

}  // namespace

// The hot spot of every solver: compiled for AVX2 and a baseline, picked at
// load time, so one binary is fast on new CPUs and still runs on old ones.
__attribute__((target_clones("avx2", "default")))
float patch_distance(const PatchSpace& space, int sx, int sy, int tx, int ty, float cutoff) {
  if (space.rotated()) return distance_rotated(space, sx, sy, tx, ty, cutoff);
  if (space.window) return distance_windowed(space, sx, sy, tx, ty, cutoff);
  if (space.target_weights) return distance_aligned<true>(space, sx, sy, tx, ty, cutoff);
  return distance_aligned<false>(space, sx, sy, tx, ty, cutoff);
}

}  // namespace tempera

#pragma once
// Guided patch distance. Every pixel of the exemplar and of the target is a
// feature vector (style channels A'/B' followed by the guide channels A_g/B_g),
// premultiplied by the square roots of their weights, so one sum of squared
// differences is the whole weighted energy of StyLit's eq. 8.1. Pixels are
// interleaved and padded to a multiple of 8 floats: a patch row is one
// contiguous run of memory that vectorizes without gathers.
#include <cmath>
#include <cstdint>
#include <vector>

#include "tempera/image.hpp"

namespace tempera {

struct FeatureImage {
  int width = 0;
  int height = 0;
  int stride = 0;  // floats per pixel, padded
  std::vector<float> data;

  FeatureImage() = default;
  FeatureImage(int w, int h, int channels);
  static int padded(int channels) { return (channels + 7) / 8 * 8; }
  float* pixel(int x, int y) { return data.data() + (std::size_t(y) * width + x) * stride; }
  const float* pixel(int x, int y) const { return data.data() + (std::size_t(y) * width + x) * stride; }
  // Writes channels of `image` into feature slots [first, first + image.channels)
  // scaled by `scale` (sqrt of the weight).
  void set_channels(int first, const ImageView& image, float scale);
  // The same with one scale per channel of `image`.
  void set_channels(int first, const ImageView& image, const std::vector<float>& scales);
};

// What a patch comparison needs: the two feature images, the patch radius and,
// for rotation-aware matching, per-pixel orientation angles (radians; the
// direction (cos a, sin a) in image coordinates, x right, y down).
struct PatchSpace {
  const FeatureImage* source = nullptr;
  const FeatureImage* target = nullptr;
  // Optional per-target-pixel channel weights (same layout as `target`), for
  // guides whose influence varies over the frame.
  const FeatureImage* target_weights = nullptr;
  int radius = 2;
  const float* source_angle = nullptr;
  const float* target_angle = nullptr;
  // Axial orientations (defined modulo pi, like hatching or a structure
  // tensor's): the smallest rotation that aligns the two directions is used,
  // so there is no branch cut (Bénard et al. 2013, §3.1).
  bool axial = true;
  // Optional weight per patch pixel, (2 radius + 1)^2 row-major, mean 1: a
  // Gaussian window (Bénard et al. 2013, eq. 1). Null = every pixel weighs 1.
  const float* window = nullptr;

  bool rotated() const { return source_angle || target_angle; }
  // Rotation from target offsets to source offsets: phi = a_src(p) - a_tgt(q).
  float rotation(int sx, int sy, int tx, int ty) const {
    float a = 0.0f;
    if (source_angle) a += source_angle[std::size_t(sy) * source->width + sx];
    if (target_angle) a -= target_angle[std::size_t(ty) * target->width + tx];
    if (axial) a -= 3.14159265f * std::round(a / 3.14159265f);
    return a;
  }
  // Distance of source centers from the border so the (possibly rotated)
  // source patch, with its bilinear footprint, lies inside the exemplar.
  int source_margin() const { return rotated() ? int(std::ceil(radius * 1.41421356f)) + 1 : radius; }
};

// Sum of squared feature differences between the source patch centered at
// (sx, sy) and the target patch centered at (tx, ty). Target patch pixels
// outside the target are skipped. Stops early and returns a value >= cutoff
// once the partial sum reaches `cutoff`.
float patch_distance(const PatchSpace& space, int sx, int sy, int tx, int ty, float cutoff);

// Source offset for a target offset (dx, dy) under rotation phi.
inline void rotate_offset(float phi, float dx, float dy, float& ox, float& oy) {
  const float c = std::cos(phi), s = std::sin(phi);
  ox = c * dx - s * dy;
  oy = s * dx + c * dy;
}

// Bilinear sample of `channels` floats of a feature or plain image at (x, y).
void sample_bilinear(const float* data, int width, int height, int stride, int channels, float x,
                     float y, float* out);

}  // namespace tempera

#pragma once
// Guided patch distance. Every pixel of the exemplar and of the target is a
// feature vector (style channels A'/B' followed by the guide channels A_g/B_g),
// premultiplied by the square roots of their weights, so one sum of squared
// differences is the whole weighted energy of StyLit's eq. 8.1. Pixels are
// interleaved, not padded: a patch row is one contiguous run of memory that
// vectorizes without gathers, and as few bytes as its channels (StyLit's
// 9 channels padded to 16 were 44% zeros, in memory and in the cache lines
// a random candidate misses). The search is
// bound by memory latency (a random candidate's rows are cache misses), so
// the features are stored quantized where the distance allows it (see
// FeatureImage::quantize and the feature_precision option).
#include <cmath>
#include <cstdint>
#include <vector>

#include "tempera/engine/huge_pages.hpp"
#include "tempera/engine/image.hpp"

namespace tempera {

// One write of feature channels: channel c of `image`, times scales[c], goes
// to feature slot first + c of every pixel. A level's features are a list of
// writes applied in order (a later write replaces an earlier one's slots), so
// the fixed-point range can be read off the writes before any feature exists.
struct ChannelWrite {
  int first = 0;
  ImageView image;
  std::vector<float> scales;  // one per channel of `image`
};

struct FeatureImage {
  int width = 0;
  int height = 0;
  int stride = 0;  // floats (or fixed-point values) per pixel: the channels
  std::vector<float> data;  // float features; empty once quantized
  // Quantized features (after quantize()): channel c of a pixel holds
  // round((v - offset[c]) / step), clamped to [0, fixed_max]. One step for all
  // channels, so the integer SSD times step^2 is the float SSD: the features
  // are weighted already, and one absolute precision fits the metric. 12 bits
  // in int16 (`fixed`) or 8 bits in bytes (`fixed8`) halve or quarter the
  // bytes a random candidate touches; integer sums are exact, so the SIMD and
  // scalar kernels agree to the bit.
  std::vector<std::int16_t, HugePageAllocator<std::int16_t>> fixed;
  std::vector<std::uint8_t, HugePageAllocator<std::uint8_t>> fixed8;
  std::vector<float> offset;
  float step = 0.0f;
  int fixed_max = 0;  // 0: float; kFixed12 (int16 storage) or kFixed8 (bytes)
  static constexpr int kFixed12 = 4095, kFixed8 = 255;

  FeatureImage() = default;
  FeatureImage(int w, int h, int channels);
  // Fixed-point features (see quantize) with every slot holding the code of
  // 0, what a float feature image starts with: built this way and written
  // with set_channels, they equal float features quantized afterwards, without
  // the float copy (twice their size) ever being held.
  static FeatureImage fixed_point(int w, int h, int channels, const std::vector<float>& channel_offset,
                                  float quant_step, int max_value);
  // A w x h feature image stored like this one (float, or fixed point with
  // its offsets and step), every slot holding 0.
  FeatureImage like(int w, int h) const {
    return quantized() ? fixed_point(w, h, stride, offset, step, fixed_max) : FeatureImage(w, h, stride);
  }
  bool quantized() const { return fixed_max > 0; }
  bool bytes() const { return fixed_max == kFixed8; }
  float* pixel(int x, int y) { return data.data() + index(x, y); }
  const float* pixel(int x, int y) const { return data.data() + index(x, y); }
  const std::int16_t* fixed_pixel(int x, int y) const { return fixed.data() + index(x, y); }
  const std::uint8_t* fixed8_pixel(int x, int y) const { return fixed8.data() + index(x, y); }
  // Start of pixel (x, y) in whichever storage is in use, and its size.
  const char* pixel_bytes(int x, int y) const {
    if (!quantized()) return reinterpret_cast<const char*>(pixel(x, y));
    return bytes() ? reinterpret_cast<const char*>(fixed8_pixel(x, y)) : reinterpret_cast<const char*>(fixed_pixel(x, y));
  }
  int bytes_per_pixel() const { return stride * int(!quantized() ? sizeof(float) : bytes() ? 1 : sizeof(std::int16_t)); }
  // Writes channels of `image` into feature slots [first, first + image.channels)
  // scaled by `scale` (sqrt of the weight).
  void set_channels(int first, const ImageView& image, float scale);
  // The same with one scale per channel of `image`.
  void set_channels(int first, const ImageView& image, const std::vector<float>& scales);
  // Applies `writes` in order.
  void set_channels(const std::vector<ChannelWrite>& writes);
  // Sets slots [first, first + count) of every pixel to 0.
  void zero_channels(int first, int count);
  // Replaces the float features by fixed-point ones in [0, max_value]
  // (kFixed12 or kFixed8) with these channel offsets (stride values) and step;
  // frees the floats.
  void quantize(const std::vector<float>& channel_offset, float quant_step, int max_value);

 private:
  std::size_t index(int x, int y) const { return (std::size_t(y) * width + x) * stride; }
  void store(std::size_t i, float v);
  float code(std::size_t slot, float v) const;  // the fixed-point value of v in slot `slot`
  void use_fixed_point(const std::vector<float>& channel_offset, float quant_step, int max_value);
};

// Offsets and step that quantize `source` (all channels) and `target`
// (channels from `target_first` on: the target's style is not known yet and
// lies in the source's range) into [0, max_value] without clipping: the
// per-channel minimum, and the widest channel range / max_value as the step.
void fixed_point_range(const FeatureImage& source, const FeatureImage& target, int target_first, int max_value,
                       std::vector<float>& offset, float& step);

// The same offsets and step for the features that `source` and `target`
// (lists of writes, see ChannelWrite) would build, read off the writes: only
// each slot's last write counts, and slots no write reaches hold 0.
void fixed_point_range(const std::vector<ChannelWrite>& source, const std::vector<ChannelWrite>& target, int stride,
                       int target_first, int max_value, std::vector<float>& offset, float& step);

// Exact integer SSD of n fixed-point values (at most 12 bits), with the kernel
// the CPU supports (AVX-512BW, AVX2, or scalar); `kernel` forces one, for tests.
enum class FixedKernel { Best, Scalar, Avx2, Avx512 };
bool fixed_kernel_supported(FixedKernel kernel);
std::int64_t fixed_ssd(const std::int16_t* a, const std::int16_t* b, int n, FixedKernel kernel = FixedKernel::Best);
std::int64_t fixed_ssd(const std::uint8_t* a, const std::uint8_t* b, int n, FixedKernel kernel = FixedKernel::Best);
// The SSD of a whole patch: `rows` rows of n values, pitch_a and pitch_b
// values apart, summed row by row while the sum is below `limit` (the early
// exit: the result is the full sum, or the first partial sum >= limit).
std::int64_t fixed_patch_ssd(const std::int16_t* a, std::size_t pitch_a, const std::int16_t* b, std::size_t pitch_b,
                             int rows, int n, std::int64_t limit, FixedKernel kernel = FixedKernel::Best);
std::int64_t fixed_patch_ssd(const std::uint8_t* a, std::size_t pitch_a, const std::uint8_t* b, std::size_t pitch_b,
                             int rows, int n, std::int64_t limit, FixedKernel kernel = FixedKernel::Best);

// What a patch comparison needs: the two feature images, the patch radius and,
// for rotation-aware matching, per-pixel orientation angles (radians; the
// direction (cos a, sin a) in image coordinates, x right, y down).
struct PatchSpace {
  const FeatureImage* source = nullptr;
  const FeatureImage* target = nullptr;
  // Optional per-target-pixel channel weights (same layout as `target`), for
  // guides whose influence varies over the frame.
  const FeatureImage* target_weights = nullptr;
  // With target_weights over quantized features: per target pixel, 1 where
  // some channel's weight is not 1 (weighted_pixels), and 1 where the patch
  // centred there covers such a pixel (weighted_patches). Other patches take
  // the fixed-point kernel as they are; these are corrected pixel by pixel.
  const std::uint8_t* weighted_pixels = nullptr;
  const std::uint8_t* weighted_patches = nullptr;
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
  // The window repeated for each of a pixel's `stride` channels
  // (expand_window): an axis-aligned patch row is then one weighted run, as
  // long as the row's features. Without it a windowed patch is summed as the
  // rotated ones are.
  const float* window_channels = nullptr;

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

// The window (side x side weights) with each weight repeated `stride` times,
// row-major: PatchSpace::window_channels.
std::vector<float> expand_window(const float* window, int radius, int stride);

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

// Fixed-point features: the SIMD kernels agree with the scalar one to the
// bit, the quantized distance is the float one within its rounding, and the
// engine's int16 path stays within 2% of the float path.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "tempera/engine/patch_distance.hpp"
#include "tempera/engine/synthesis.hpp"
#include "test_inputs.hpp"

using namespace tempera;
using tempera::test_inputs::noise_texture;

namespace {

Image ramp_guide(int w, int h) {
  Image g(w, h, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      g.at(x, y, 0) = float(x) / w + 0.05f * std::sin(0.7f * y);
      g.at(x, y, 1) = float(y) / h;
    }
  return g;
}

}  // namespace

namespace {

// Every kernel the CPU has against a plain sum, on random and on extreme
// values (the largest differences must not overflow a lane), aligned and not.
template <class T>
int check_kernels(int max_value) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> value(0, max_value);
  int checked = 0;
  for (int n : {0, 1, 7, 8, 15, 16, 24, 40, 56, 72, 200, 1000, 1024, 1032, 5000}) {
    std::vector<T> a(std::size_t(n) + 1), b(std::size_t(n) + 1);
    for (int trial = 0; trial < 4; ++trial) {
      for (std::size_t i = 0; i < a.size(); ++i) {
        a[i] = T(value(rng));
        b[i] = trial == 3 ? T(a[i] > max_value / 2 ? 0 : max_value) : T(value(rng));
      }
      for (int shift : {0, 1}) {
        std::int64_t naive = 0;
        for (int i = shift; i < n + shift; ++i) naive += std::int64_t(a[i] - b[i]) * (a[i] - b[i]);
        for (FixedKernel k : {FixedKernel::Scalar, FixedKernel::Avx2, FixedKernel::Avx512, FixedKernel::Best}) {
          if (!fixed_kernel_supported(k)) continue;
          EXPECT_EQ(fixed_ssd(a.data() + shift, b.data() + shift, n, k), naive)
              << "n " << n << " kernel " << int(k) << " shift " << shift;
          ++checked;
        }
      }
    }
  }
  return checked;
}

}  // namespace

TEST(FixedFeatures, SimdKernelsAgreeWithScalarExactly) {
  const int checked16 = check_kernels<std::int16_t>(FeatureImage::kFixed12);
  const int checked8 = check_kernels<std::uint8_t>(FeatureImage::kFixed8);
  // The machines this runs on have AVX2: more than the scalar kernel was tested.
  if (fixed_kernel_supported(FixedKernel::Avx2)) {
    EXPECT_GT(checked16, 15 * 4 * 2 * 2);
    EXPECT_GT(checked8, 15 * 4 * 2 * 2);
  }
}

namespace {

// Whole-patch kernels against row sums with the same early exit: short rows
// (reduced in 32 bits), long ones (the row kernels), extreme values, limits
// that stop at every row and never.
template <class T>
int check_patch_kernels(int max_value) {
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> value(0, max_value);
  int checked = 0;
  // kShortRow = 128; rows of unpadded pixels (9 channels: 45 values a 5-pixel row) and clipped ones (< 8)
  for (int n : {3, 5, 8, 9, 13, 16, 24, 40, 45, 56, 63, 72, 96, 104, 120, 127, 128, 136, 248}) {
    const int rows = 7;
    const std::size_t pitch_a = std::size_t(n) + 24, pitch_b = std::size_t(n) + 8;
    std::vector<T> a(pitch_a * rows), b(pitch_b * rows);
    for (int trial = 0; trial < 4; ++trial) {  // 3: every difference the largest, the 32-bit bound
      for (auto& v : a) v = trial == 3 ? T(max_value) : T(value(rng));
      for (std::size_t i = 0; i < b.size(); ++i)
        b[i] = trial == 3 ? T(0) : trial == 2 ? T(a[i % pitch_a] > max_value / 2 ? 0 : max_value) : T(value(rng));
      std::vector<std::int64_t> partial(rows + 1, 0);  // partial[k]: the first k rows
      for (int k = 0; k < rows; ++k) {
        std::int64_t row = 0;
        for (int i = 0; i < n; ++i) {
          const std::int64_t d = std::int64_t(a[k * pitch_a + i]) - b[k * pitch_b + i];
          row += d * d;
        }
        partial[k + 1] = partial[k] + row;
      }
      std::vector<std::int64_t> limits = {0, 1, std::numeric_limits<std::int64_t>::max()};
      for (int k = 1; k <= rows; ++k) limits.push_back(partial[k]), limits.push_back(partial[k] + 1);
      for (std::int64_t limit : limits) {
        int k = 1;
        while (k < rows && partial[k] < limit) ++k;
        const std::int64_t expected = limit <= 0 ? 0 : partial[k];
        for (FixedKernel kernel : {FixedKernel::Scalar, FixedKernel::Avx2, FixedKernel::Avx512, FixedKernel::Best}) {
          if (!fixed_kernel_supported(kernel)) continue;
          EXPECT_EQ(fixed_patch_ssd(a.data(), pitch_a, b.data(), pitch_b, rows, n, limit, kernel), expected)
              << "n " << n << " limit " << limit << " kernel " << int(kernel);
          ++checked;
        }
      }
    }
  }
  return checked;
}

}  // namespace

TEST(FixedFeatures, PatchKernelsStopWhereTheRowSumsDo) {
  const int checked16 = check_patch_kernels<std::int16_t>(FeatureImage::kFixed12);
  const int checked8 = check_patch_kernels<std::uint8_t>(FeatureImage::kFixed8);
  if (fixed_kernel_supported(FixedKernel::Avx2)) {  // more than the scalar kernel was tested
    EXPECT_GT(checked16, 9 * 3 * 17 * 2);
    EXPECT_GT(checked8, 9 * 3 * 17 * 2);
  }
}

TEST(FixedFeatures, QuantizedDistanceMatchesFloatWithinRounding) {
  const int w = 40, h = 30, channels = 7;
  const Image src = noise_texture(w, h, channels, 1), tgt = noise_texture(w, h, channels, 2);
  FeatureImage fs(w, h, channels), ft(w, h, channels);
  fs.set_channels(0, src.view(), 0.8f);
  ft.set_channels(0, tgt.view(), 0.8f);
  PatchSpace fspace;
  fspace.source = &fs, fspace.target = &ft;
  for (const auto& [max_value, tolerance] : {std::pair{FeatureImage::kFixed12, 2e-3}, std::pair{FeatureImage::kFixed8, 3e-2}}) {
    FeatureImage qs = fs, qt = ft;
    std::vector<float> offset;
    float step = 0.0f;
    fixed_point_range(qs, qt, 0, max_value, offset, step);
    qs.quantize(offset, step, max_value);
    qt.quantize(offset, step, max_value);
    EXPECT_TRUE(qs.data.empty());  // the floats are freed
    ASSERT_TRUE(qs.quantized());
    EXPECT_EQ(qs.bytes_per_pixel(), max_value == FeatureImage::kFixed8 ? 7 : 14);  // unpadded
    PatchSpace qspace;
    qspace.source = &qs, qspace.target = &qt;
    std::mt19937 rng(3);
    double max_rel = 0.0;
    bool differs = false;
    for (int k = 0; k < 500; ++k) {
      const int sx = 2 + int(rng() % (w - 4)), sy = 2 + int(rng() % (h - 4));
      const int tx = int(rng() % w), ty = int(rng() % h);
      const float f = patch_distance(fspace, sx, sy, tx, ty, 1e30f);
      const float q = patch_distance(qspace, sx, sy, tx, ty, 1e30f);
      max_rel = std::max(max_rel, std::abs(double(q) - f) / f);
      differs |= q != f;
    }
    EXPECT_LT(max_rel, tolerance) << max_value;
    EXPECT_TRUE(differs);  // it is the fixed-point path that ran
    // The early exit still returns at least the cutoff.
    EXPECT_GE(patch_distance(qspace, 5, 5, 20, 20, 0.01f), 0.01f);
  }
}

TEST(FixedFeatures, FixedPointSynthesisStaysCloseToFloat) {
  const Image style = noise_texture(64, 64, 3, 4);
  const Image sg = ramp_guide(64, 64), tg = ramp_guide(72, 56);
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("g", sg.view(), tg.view(), 2.0f);
  SynthesisOptions fixed;
  fixed.threads = 2;
  // Plain nearest neighbours: the error budget's knee, on a frame this small,
  // moves the final energy by 10% from one EM iteration to the next either
  // way (it did before its seeding from the previous assignment, too), which
  // would hide what the features' precision does.
  fixed.usage = PatchUsage::None;
  SynthesisOptions exact = fixed;
  exact.feature_precision = FeaturePrecision::Float;
  SynthesisOptions bytes = fixed;
  bytes.feature_precision = FeaturePrecision::Int8;
  const SynthesisResult a = synthesize(in, fixed), b = synthesize(in, exact), c = synthesize(in, bytes);
  const double ea = a.levels.back().energy.back(), eb = b.levels.back().energy.back();
  const double ec = c.levels.back().energy.back();
  EXPECT_NEAR(ea, eb, 0.02 * eb);
  EXPECT_NEAR(ec, eb, 0.1 * eb);  // 8-bit rounding, on a frame this small
  // On a frame this small a few hundred patches move the coverage by several
  // percent either way: the error budget's knee sits where the sorted errors
  // climb steeply, so a slightly different error curve moves its threshold
  // far. The bench holds the 2% on 1 Mpix.
  EXPECT_NEAR(c.source_coverage, b.source_coverage, 0.08 * b.source_coverage);
  EXPECT_NEAR(a.source_coverage, b.source_coverage, 0.08 * b.source_coverage);
  RecordProperty("energy", std::to_string(ea) + " " + std::to_string(ec) + " vs " + std::to_string(eb));
  // Rounding moves some matches: the option is in effect.
  EXPECT_FALSE(std::equal(a.image.data(), a.image.data() + a.image.pixel_count() * 3, b.image.data()));
}

// Per-pixel target weights (StyLit's temporal guide under occlusion_backward)
// keep the fixed-point features: patches that meet a weighted pixel are
// corrected pixel by pixel, so the quantized distance is the float weighted
// one within rounding, and patches that meet none are the plain kernel's.
TEST(FixedFeatures, WeightedPixelsKeepTheFixedPointPath) {
  const int w = 40, h = 30, channels = 6;
  const Image src = noise_texture(w, h, channels, 5), tgt = noise_texture(w, h, channels, 6);
  FeatureImage fs(w, h, channels), ft(w, h, channels), weights(w, h, channels);
  fs.set_channels(0, src.view(), 0.8f);
  ft.set_channels(0, tgt.view(), 0.8f);
  std::fill(weights.data.begin(), weights.data.end(), 1.0f);
  std::vector<std::uint8_t> weighted(std::size_t(w) * h, 0), near(std::size_t(w) * h, 0);
  for (int y = 10; y < 20; ++y)  // a disoccluded block: channels 3-5 off, and a half weight beside it
    for (int x = 10; x < 22; ++x) {
      for (int c = 3; c < 6; ++c) weights.pixel(x, y)[c] = x < 16 ? 0.0f : 0.5f;
      weighted[std::size_t(y) * w + x] = 1;
    }
  PatchSpace fspace;
  fspace.source = &fs, fspace.target = &ft, fspace.target_weights = &weights;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int dy = -fspace.radius; dy <= fspace.radius; ++dy)
        for (int dx = -fspace.radius; dx <= fspace.radius; ++dx) {
          const int px = x + dx, py = y + dy;
          if (px >= 0 && py >= 0 && px < w && py < h && weighted[std::size_t(py) * w + px])
            near[std::size_t(y) * w + x] = 1;
        }
  FeatureImage qs = fs, qt = ft;
  std::vector<float> offset;
  float step = 0.0f;
  fixed_point_range(qs, qt, 0, FeatureImage::kFixed12, offset, step);
  qs.quantize(offset, step, FeatureImage::kFixed12);
  qt.quantize(offset, step, FeatureImage::kFixed12);
  PatchSpace qspace = fspace;
  qspace.source = &qs, qspace.target = &qt;
  qspace.weighted_pixels = weighted.data(), qspace.weighted_patches = near.data();
  PatchSpace unweighted = qspace;
  unweighted.target_weights = nullptr, unweighted.weighted_pixels = nullptr, unweighted.weighted_patches = nullptr;
  std::mt19937 rng(4);
  double max_rel = 0.0;
  int corrected = 0;
  for (int k = 0; k < 800; ++k) {
    const int sx = 2 + int(rng() % (w - 4)), sy = 2 + int(rng() % (h - 4));
    const int tx = int(rng() % w), ty = int(rng() % h);
    const float f = patch_distance(fspace, sx, sy, tx, ty, 1e30f);
    const float q = patch_distance(qspace, sx, sy, tx, ty, 1e30f);
    max_rel = std::max(max_rel, std::abs(double(q) - f) / f);
    const float plain = patch_distance(unweighted, sx, sy, tx, ty, 1e30f);
    if (near[std::size_t(ty) * w + tx]) {
      corrected += q < plain;  // the weights lowered it
    } else {
      EXPECT_EQ(q, plain);  // untouched patches: the kernel's value
    }
  }
  EXPECT_LT(max_rel, 2e-3);
  EXPECT_GT(corrected, 20);
  // A corrected patch stops no earlier than its weighted value: at least the cutoff.
  const float full = patch_distance(qspace, 15, 15, 15, 15, 1e30f);
  EXPECT_GE(patch_distance(qspace, 15, 15, 15, 15, 0.5f * full), 0.5f * full);
}

// A weighted guide (a pull switched off over a block, as occlusion_backward
// does) solved on fixed-point features: the energy is no more than 2% above
// the float solve's (0.2% below it on this toy, measured), and only with
// fixed_point_weights are the features quantized.
TEST(FixedFeatures, WeightedSynthesisOnFixedPointStaysCloseToFloat) {
  const Image style = noise_texture(64, 64, 3, 7), pull = noise_texture(72, 56, 3, 8);
  const Image sg = ramp_guide(64, 64), tg = ramp_guide(72, 56);
  Image visible(72, 56, 1, 1.0f);
  for (int y = 20; y < 36; ++y)
    for (int x = 30; x < 50; ++x) visible.at(x, y, 0) = 0.0f;
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("g", sg.view(), tg.view(), 2.0f);
  in.guides.add("temporal", style.view(), pull.view(), 0.5f);
  in.target_weight_maps = {ImageView{}, visible.view()};
  SynthesisOptions exact;
  exact.threads = 2;
  exact.usage = PatchUsage::None;  // as above
  exact.guide_variance = 1.0;  // the weight map belongs to its guide, uncompressed
  SynthesisOptions fixed = exact;
  fixed.fixed_point_weights = true;
  const SynthesisResult a = synthesize(in, fixed), b = synthesize(in, exact);
  const double ea = a.levels.back().energy.back(), eb = b.levels.back().energy.back();
  EXPECT_LE(ea, 1.02 * eb);
  EXPECT_GE(ea, 0.9 * eb);  // the same problem solved, not another
  RecordProperty("energy", std::to_string(ea) + " vs " + std::to_string(eb));
  EXPECT_FALSE(std::equal(a.image.data(), a.image.data() + a.image.pixel_count() * 3, b.image.data()));
  SynthesisOptions float_features = exact;
  float_features.feature_precision = FeaturePrecision::Float;
  const SynthesisResult c = synthesize(in, float_features);  // what the default does with weights
  EXPECT_TRUE(std::equal(b.image.data(), b.image.data() + b.image.pixel_count() * 3, c.image.data()));
}

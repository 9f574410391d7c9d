// Building a level's fixed-point features straight from the float pyramids
// (ChannelWrite, FeatureImage::fixed_point): the same features as float ones
// quantized afterwards, without the float copy ever being allocated.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>

#include "tempera/engine/patch_distance.hpp"
#include "tempera/engine/solver.hpp"

using namespace tempera;

// The largest single allocation while `g_counting` is set: a replaced global
// operator new, so that a test can see which buffers a call allocates.
namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::size_t> g_largest{0};
}  // namespace

void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) {
    std::size_t cur = g_largest.load(std::memory_order_relaxed);
    while (n > cur && !g_largest.compare_exchange_weak(cur, n, std::memory_order_relaxed)) {
    }
  }
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

Image random_image(int w, int h, int c, unsigned seed, float lo, float hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  Image img(w, h, c);
  for (std::size_t i = 0; i < img.pixel_count() * c; ++i) img.data()[i] = u(rng);
  return img;
}

std::vector<float> scales(int n, float s) { return std::vector<float>(std::size_t(n), s); }

}  // namespace

// Overlapping writes (a later one replaces slots of an earlier one, whose
// values must then not widen the range), slots no write reaches, a target
// range that starts after the style slots, and both storage widths.
TEST(FeatureBuild, FixedPointFromWritesEqualsQuantizedFloat) {
  const int w = 37, h = 23, channels = 11;
  const Image all = random_image(w, h, 9, 1, -3.0f, 5.0f);     // slots 0..8
  const Image style = random_image(w, h, 3, 2, 0.0f, 1.0f);    // replaces slots 0..2
  const Image wide = random_image(w, h, 2, 3, -40.0f, 40.0f);  // slots 3..4, replaced below
  const Image guide = random_image(w, h, 2, 4, 0.2f, 0.7f);    // replaces slots 3..4
  const Image last = random_image(w, h, 2, 5, 1.0f, 2.0f);     // slots 9..10 of the target only
  const std::vector<ChannelWrite> source = {{0, all.view(), scales(9, 1.0f)},
                                            {0, style.view(), {0.5f, 1.5f, 2.0f}},
                                            {9, last.view(), scales(2, 0.3f)}};
  const std::vector<ChannelWrite> target = {{3, wide.view(), scales(2, 1.0f)},
                                            {3, guide.view(), scales(2, 0.8f)},
                                            {0, style.view(), scales(3, 9.0f)}};  // below target_first: ignored
  for (int max_value : {FeatureImage::kFixed12, FeatureImage::kFixed8}) {
    FeatureImage fs(w, h, channels), ft(w, h, channels);
    fs.set_channels(source);
    ft.set_channels(target);
    std::vector<float> offset_float, offset_writes;
    float step_float = 0, step_writes = 0;
    fixed_point_range(fs, ft, 3, max_value, offset_float, step_float);
    fixed_point_range(source, target, channels, 3, max_value, offset_writes, step_writes);
    ASSERT_EQ(offset_writes, offset_float);
    ASSERT_EQ(step_writes, step_float);
    fs.quantize(offset_float, step_float, max_value);
    ft.quantize(offset_float, step_float, max_value);
    FeatureImage ds = FeatureImage::fixed_point(w, h, channels, offset_writes, step_writes, max_value);
    FeatureImage dt = FeatureImage::fixed_point(w, h, channels, offset_writes, step_writes, max_value);
    ds.set_channels(source);
    dt.set_channels(target);
    EXPECT_TRUE(ds.data.empty());
    EXPECT_EQ(ds.fixed, fs.fixed);
    EXPECT_EQ(dt.fixed, ft.fixed);
    EXPECT_EQ(ds.fixed8, fs.fixed8);
    EXPECT_EQ(dt.fixed8, ft.fixed8);
    // The replaced wide values would have set the step: the range is the final values'.
    EXPECT_LT(step_writes * float(max_value), 20.0f);
  }
}

// The level's build (here through energy()) never allocates a buffer the size
// of a float feature image: the int16 features are written directly. With
// float features the same count sees them, so the counter is live.
TEST(FeatureBuild, LevelBuildAllocatesNoFloatFeatureImage) {
  const int s = 256;
  const Image style = random_image(s, s, 3, 6, 0.0f, 1.0f), sg = random_image(s, s, 2, 7, 0.0f, 1.0f),
              tg = random_image(s, s, 2, 8, 0.0f, 1.0f);
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("g", sg.view(), tg.view());
  OffsetField field(s, s);
  for (int y = 0; y < s; ++y)
    for (int x = 0; x < s; ++x)
      field.set_position(std::size_t(y) * s + x, float(std::clamp(x, 2, s - 3)), float(std::clamp(y, 2, s - 3)));
  const std::size_t float_features = std::size_t(s) * s * 5 * sizeof(float);
  auto largest_during_energy = [&](FeaturePrecision precision, double& energy) {
    SynthesisOptions opt;
    opt.feature_precision = precision;
    opt.threads = 1;
    const Solver solver(in, opt);
    g_largest = 0;
    g_counting = true;
    energy = solver.energy(0, field, style);
    g_counting = false;
    return g_largest.load();
  };
  double e_fixed = 0, e_float = 0;
  const std::size_t fixed = largest_during_energy(FeaturePrecision::Int16, e_fixed);
  const std::size_t floats = largest_during_energy(FeaturePrecision::Float, e_float);
  EXPECT_LT(fixed, float_features) << "a float copy of the features was allocated";
  EXPECT_GE(fixed, float_features / 2);  // the int16 features themselves
  EXPECT_GE(floats, float_features);
  EXPECT_NEAR(e_fixed, e_float, 0.02 * e_float);  // the same features, to the quantization step
}

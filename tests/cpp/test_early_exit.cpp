// The patch distance's early exit (it stops summing rows once the partial sum
// reaches the cutoff): every accept/reject decision it leads to is the one the
// full sum gives, ties included, on every storage and patch kind.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "tempera/engine/patch_distance.hpp"

using namespace tempera;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

FeatureImage random_features(int w, int h, int channels, unsigned seed, bool coarse) {
  std::mt19937 rng(seed);
  FeatureImage f(w, h, channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c)
        // Coarse values repeat, so different patches tie on their distance.
        f.pixel(x, y)[c] = coarse ? float(rng() % 3) * 0.25f : float(rng() % 10000) * 1e-4f;
  return f;
}

void quantize_pair(FeatureImage& s, FeatureImage& t, int max_value) {
  std::vector<float> offset;
  float step = 0.0f;
  fixed_point_range(s, t, 0, max_value, offset, step);
  s.quantize(offset, step, max_value);
  t.quantize(offset, step, max_value);
}

// Checks many (source, target, cutoff) triples; cutoffs are the full distance
// itself (a tie), its float neighbours, the partial sums of its rows and
// random fractions of it. Counts in `early` the cut-off calls that returned early.
void check_decisions(const PatchSpace& space, unsigned seed, int& early) {
  std::mt19937 rng(seed);
  const int w = space.source->width, h = space.source->height, margin = space.source_margin();
  early = 0;
  for (int k = 0; k < 400; ++k) {
    const int sx = margin + int(rng() % unsigned(w - 2 * margin)), sy = margin + int(rng() % unsigned(h - 2 * margin));
    const int tx = int(rng() % unsigned(space.target->width)), ty = int(rng() % unsigned(space.target->height));
    const float full = patch_distance(space, sx, sy, tx, ty, kInf);
    std::vector<float> cutoffs = {full, std::nextafter(full, 0.0f), std::nextafter(full, kInf), 0.0f};
    for (float f : {0.1f, 0.3f, 0.5f, 0.7f, 0.9f, 0.99f, 1.01f, 2.0f}) cutoffs.push_back(full * f);
    for (float cutoff : cutoffs) {
      const float d = patch_distance(space, sx, sy, tx, ty, cutoff);
      const bool accept = d < cutoff, accept_full = full < cutoff;
      ASSERT_EQ(accept, accept_full) << "cutoff " << cutoff << " full " << full << " early " << d;
      if (accept)
        ASSERT_EQ(d, full) << "an accepted distance must be the full sum";
      else
        ASSERT_GE(d, cutoff);
      early += d != full;
    }
  }
}

}  // namespace

TEST(EarlyExit, DecidesAsTheFullSumOnEveryStorage) {
  const int w = 24, h = 20, channels = 7;
  for (bool coarse : {false, true}) {
    for (int max_value : {0, FeatureImage::kFixed12, FeatureImage::kFixed8}) {
      FeatureImage s = random_features(w, h, channels, 1, coarse), t = random_features(w, h, channels, 2, coarse);
      if (max_value) quantize_pair(s, t, max_value);
      PatchSpace space;
      space.source = &s, space.target = &t;
      int early = 0;
      check_decisions(space, 3, early);
      // The early exit must actually be exercised, or the test proves nothing.
      EXPECT_GT(early, 100) << "precision " << max_value << " coarse " << coarse;
    }
  }
}

TEST(EarlyExit, DecidesAsTheFullSumForWeightedWindowedAndRotatedPatches) {
  const int w = 24, h = 20, channels = 5, r = 2, side = 2 * r + 1;
  const FeatureImage s = random_features(w, h, channels, 4, false), t = random_features(w, h, channels, 5, false);
  const FeatureImage weights = random_features(w, h, channels, 6, false);
  std::vector<float> window(side * side), angle_s(std::size_t(w) * h), angle_t(std::size_t(w) * h);
  std::mt19937 rng(7);
  for (float& v : window) v = 0.2f + float(rng() % 100) * 0.016f;
  for (float& v : angle_s) v = float(rng() % 628) * 0.01f;
  for (float& v : angle_t) v = float(rng() % 628) * 0.01f;
  PatchSpace weighted, windowed, rotated;
  weighted.source = windowed.source = rotated.source = &s;
  weighted.target = windowed.target = rotated.target = &t;
  weighted.target_weights = &weights;
  windowed.window = window.data();
  const std::vector<float> window_channels = expand_window(window.data(), r, channels);
  windowed.window_channels = window_channels.data();
  rotated.source_angle = angle_s.data(), rotated.target_angle = angle_t.data(), rotated.window = window.data();
  int early = 0;
  check_decisions(weighted, 8, early);
  EXPECT_GT(early, 100);
  check_decisions(windowed, 9, early);
  EXPECT_GT(early, 100);
  check_decisions(rotated, 10, early);
  EXPECT_GT(early, 100);
}

TEST(WindowedDistance, RowsUnderTheExpandedWindowSumAsPixelByPixel) {
  // The windowed patch rows (window_channels) against the same window applied
  // pixel by pixel (the rotated patches' loop, at no rotation), with and
  // without per-pixel channel weights, targets over the border included.
  const int w = 30, h = 24, channels = 15, r = 4, side = 2 * r + 1;
  const FeatureImage s = random_features(w, h, channels, 11, false), t = random_features(w, h, channels, 12, false);
  const FeatureImage weights = random_features(w, h, channels, 13, false);
  std::vector<float> window(side * side);
  std::mt19937 rng(14);
  for (float& v : window) v = 0.2f + float(rng() % 100) * 0.016f;
  const std::vector<float> window_channels = expand_window(window.data(), r, channels);
  for (bool weighted : {false, true}) {
    PatchSpace rows, pixels;
    rows.source = pixels.source = &s;
    rows.target = pixels.target = &t;
    rows.radius = pixels.radius = r;
    rows.window = pixels.window = window.data();
    rows.window_channels = window_channels.data();
    if (weighted) rows.target_weights = pixels.target_weights = &weights;
    for (int k = 0; k < 300; ++k) {
      const int sx = r + int(rng() % unsigned(w - 2 * r)), sy = r + int(rng() % unsigned(h - 2 * r));
      const int tx = int(rng() % unsigned(w)), ty = int(rng() % unsigned(h));
      const float a = patch_distance(rows, sx, sy, tx, ty, kInf), b = patch_distance(pixels, sx, sy, tx, ty, kInf);
      ASSERT_NEAR(a, b, 1e-5f * b) << weighted << " " << tx << " " << ty;
    }
  }
}

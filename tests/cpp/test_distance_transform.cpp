#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tempera/engine/distance_transform.hpp"
#include "tempera/engine/error.hpp"

using namespace tempera;

namespace {

// Reference: distance from every pixel to every line pixel.
float brute_force(const Image& mask, int x, int y) {
  float best = INFINITY;
  for (int j = 0; j < mask.height(); ++j)
    for (int i = 0; i < mask.width(); ++i)
      if (mask.at(i, j, 0) > 0.5f) best = std::min(best, std::hypot(float(i - x), float(j - y)));
  return best;
}

Image random_mask(int w, int h, float density, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Image mask(w, h, 1);
  for (int i = 0; i < w * h; ++i) mask.data()[i] = u(rng) < density ? 1.0f : 0.0f;
  return mask;
}

}  // namespace

TEST(DistanceTransform, MatchesBruteForce) {
  for (unsigned seed : {1u, 2u, 3u}) {
    Image mask = random_mask(23, 17, 0.04f, seed);
    const float d_max = 100.0f;  // beyond the diagonal: no clamping
    Image d = line_distance(mask.view(), d_max);
    for (int y = 0; y < 17; ++y)
      for (int x = 0; x < 23; ++x)
        ASSERT_NEAR(d.at(x, y, 0), std::min(brute_force(mask, x, y), d_max) / d_max, 1e-5f)
            << "seed " << seed << " x=" << x << " y=" << y;
  }
}

TEST(DistanceTransform, ClampsAtDmax) {
  Image mask = random_mask(31, 19, 0.01f, 4);
  Image d = line_distance(mask.view(), 3.0f);
  int saturated = 0;
  for (int y = 0; y < 19; ++y)
    for (int x = 0; x < 31; ++x) {
      const float expected = std::min(brute_force(mask, x, y), 3.0f) / 3.0f;
      ASSERT_NEAR(d.at(x, y, 0), expected, 1e-5f);
      ASSERT_LE(d.at(x, y, 0), 1.0f);
      saturated += d.at(x, y, 0) == 1.0f;
    }
  EXPECT_GT(saturated, 0);
}

TEST(DistanceTransform, SinglePixelGivesEuclideanDistance) {
  Image mask(20, 15, 1);
  mask.at(5, 7, 0) = 1.0f;
  Image d = line_distance(mask.view(), 50.0f);
  EXPECT_EQ(d.at(5, 7, 0), 0.0f);
  for (int y = 0; y < 15; ++y)
    for (int x = 0; x < 20; ++x)
      ASSERT_NEAR(d.at(x, y, 0) * 50.0f, std::sqrt(float((x - 5) * (x - 5) + (y - 7) * (y - 7))), 1e-4f);
}

TEST(DistanceTransform, EmptyMaskIsAllOne) {
  Image mask(9, 4, 1, 0.5f);  // 0.5 is not above the threshold
  Image d = line_distance(mask.view());
  for (std::size_t i = 0; i < d.pixel_count(); ++i) EXPECT_EQ(d.data()[i], 1.0f);
}

TEST(DistanceTransform, RejectsBadInputs) {
  Image mask(8, 8, 1), rgb(8, 8, 3);
  EXPECT_THROW(line_distance(mask.view(), 0.0f), ValueError);
  EXPECT_THROW(line_distance(mask.view(), -2.0f), ValueError);
  EXPECT_THROW(line_distance(mask.view(), INFINITY), ValueError);
  EXPECT_THROW(line_distance(rgb.view()), ValueError);
  EXPECT_THROW(line_distance(ImageView{}), ValueError);
  mask.at(1, 2, 0) = std::nanf("");
  EXPECT_THROW(line_distance(mask.view()), ValueError);
}

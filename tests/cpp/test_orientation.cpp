#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tempera/engine/error.hpp"
#include "tempera/engine/orientation.hpp"

using namespace tempera;

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Sinusoidal stripes running along direction `angle` (x right, y down),
// period 10 px, repeated in `channels` channels.
Image stripes(float angle, int channels = 1, int w = 64, int h = 48) {
  const float nx = -std::sin(angle), ny = std::cos(angle);  // across the stripes
  Image img(w, h, channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c)
        img.at(x, y, c) = 0.5f + 0.5f * std::sin(2.0f * kPi * (nx * float(x) + ny * float(y)) / 10.0f);
  return img;
}

// Distance between two undirected angles (mod π).
float angle_error(float a, float b) {
  const float d = std::fmod(std::fabs(a - b), kPi);
  return std::min(d, kPi - d);
}

// Checks the interior (away from the replicated border) against `expected`.
void expect_orientation(const Image& img, float expected, float tolerance) {
  Image o = orientation_from_tensor(structure_tensor(img.view(), 2.0f).view());
  ASSERT_EQ(o.channels(), 2);
  for (int y = 8; y < o.height() - 8; ++y)
    for (int x = 8; x < o.width() - 8; ++x) {
      const float a = o.at(x, y, 0);
      ASSERT_TRUE(a >= 0.0f && a < kPi) << a;
      ASSERT_LT(angle_error(a, expected), tolerance) << "x=" << x << " y=" << y << " angle " << a;
      ASSERT_GT(o.at(x, y, 1), 0.9f) << "coherence at x=" << x << " y=" << y;
    }
}

}  // namespace

TEST(Orientation, HorizontalStripesGiveZero) { expect_orientation(stripes(0.0f), 0.0f, 0.01f); }

TEST(Orientation, VerticalStripesGiveHalfPi) { expect_orientation(stripes(kPi / 2), kPi / 2, 0.01f); }

TEST(Orientation, ObliqueStripesWithinThreeDegrees) {
  const float degree = kPi / 180.0f;
  expect_orientation(stripes(30.0f * degree), 30.0f * degree, 3.0f * degree);
  expect_orientation(stripes(120.0f * degree), 120.0f * degree, 3.0f * degree);
}

TEST(Orientation, RgbUsesTheMeanOfTheFirstThreeChannels) {
  Image gray = stripes(0.5f, 1), rgba = stripes(0.5f, 4);
  for (int y = 0; y < rgba.height(); ++y)
    for (int x = 0; x < rgba.width(); ++x) rgba.at(x, y, 3) = float(x % 2);  // alpha is ignored
  Image a = structure_tensor(gray.view()), b = structure_tensor(rgba.view());
  ASSERT_EQ(b.channels(), 3);
  for (std::size_t i = 0; i < a.pixel_count() * 3; ++i) ASSERT_NEAR(a.data()[i], b.data()[i], 1e-6f);
}

TEST(Orientation, FlatImageHasZeroCoherenceAndFiniteAngles) {
  Image flat(16, 16, 3, 0.4f);
  Image o = orientation_from_tensor(structure_tensor(flat.view(), 2.0f).view());
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      EXPECT_TRUE(std::isfinite(o.at(x, y, 0)));
      EXPECT_NEAR(o.at(x, y, 1), 0.0f, 1e-6f);
    }
}

TEST(Orientation, CoherenceIsLowWhereOrientationsCross) {
  // Sum of horizontal and vertical stripes: no dominant direction.
  Image a = stripes(0.0f), b = stripes(kPi / 2);
  for (std::size_t i = 0; i < a.pixel_count(); ++i) a.data()[i] += b.data()[i];
  Image o = orientation_from_tensor(structure_tensor(a.view(), 4.0f).view());
  EXPECT_LT(o.at(32, 24, 1), 0.2f);
}

TEST(Orientation, RejectsBadInputs) {
  Image img(8, 8, 1), two(8, 8, 2);
  EXPECT_THROW(structure_tensor(img.view(), -1.0f), ValueError);
  EXPECT_THROW(structure_tensor(img.view(), std::nanf("")), ValueError);
  EXPECT_THROW(structure_tensor(ImageView{}, 2.0f), ValueError);
  EXPECT_THROW(orientation_from_tensor(two.view()), ValueError);
  img.at(3, 3, 0) = std::nanf("");
  EXPECT_THROW(structure_tensor(img.view(), 2.0f), ValueError);
  EXPECT_NO_THROW(structure_tensor(two.view(), 0.0f));
}

#include <gtest/gtest.h>

#include <cmath>

#include "tempera/methods/lazyfluids/alpha_segments.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/engine/gaussian_blur.hpp"

using namespace tempera;

TEST(GaussianBlur, KeepsTheMeanAndMatchesTheAnalyticImpulseResponse) {
  Image impulse(41, 41, 2);
  impulse.at(20, 20, 0) = 1;
  impulse.at(20, 20, 1) = 2;
  const float sigma = 2;
  const Image out = gaussian_blur(impulse.view(), sigma);
  double sum = 0;
  for (int y = 0; y < 41; ++y)
    for (int x = 0; x < 41; ++x) sum += out.at(x, y, 0);
  EXPECT_NEAR(sum, 1.0, 1e-5);
  // Separable Gaussian: the ratio of two taps is exp(-d²/2σ²) per axis.
  EXPECT_NEAR(out.at(22, 20, 0) / out.at(20, 20, 0), std::exp(-4.0 / (2 * sigma * sigma)), 1e-3);
  EXPECT_NEAR(out.at(21, 21, 0) / out.at(20, 20, 0), std::exp(-2.0 / (2 * sigma * sigma)), 1e-3);
  EXPECT_FLOAT_EQ(out.at(23, 18, 1), 2 * out.at(23, 18, 0));  // every channel, alike
}

TEST(GaussianBlur, ClampsTheEdgesSoAConstantStaysConstant) {
  Image flat(7, 5, 1, 0.25f);
  const Image out = gaussian_blur(flat.view(), 3);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) EXPECT_NEAR(out.at(x, y, 0), 0.25f, 1e-6);
  EXPECT_EQ(gaussian_blur(flat.view(), 0).at(3, 3, 0), 0.25f);
}

TEST(AlphaSegments, ThresholdsTheBlurredAlphaIntoBoundaryInteriorAndOutside) {
  Image a(3, 1, 1);
  a.at(0, 0, 0) = 0.1f;   // α <= l: outside
  a.at(1, 0, 0) = 0.5f;   // boundary
  a.at(2, 0, 0) = 0.9f;   // α >= u: interior
  const Image labels = alpha_segment_labels(a.view(), 0.1f, 0.9f);
  EXPECT_EQ(labels.at(0, 0, 0), outside_label);
  EXPECT_EQ(labels.at(1, 0, 0), boundary_label);
  EXPECT_EQ(labels.at(2, 0, 0), interior_label);
  EXPECT_THROW(alpha_segment_labels(a.view(), 0.9f, 0.1f), ValueError);
}

TEST(AlphaSegments, AHardDiscGetsABoundaryRingAroundItsEdge) {
  const int n = 40;
  Image disc(n, n, 1);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) disc.at(x, y, 0) = std::hypot(x - 20.0, y - 20.0) < 12 ? 1.0f : 0.0f;
  const AlphaSegments s = alpha_segments(disc.view(), AlphaSegmentOptions{});
  EXPECT_EQ(s.labels.at(20, 20, 0), interior_label);
  EXPECT_EQ(s.labels.at(32, 20, 0), boundary_label);  // on the edge
  EXPECT_EQ(s.labels.at(0, 0, 0), outside_label);
  EXPECT_EQ(s.inside.at(0, 0, 0), 0.0f);
  EXPECT_EQ(s.inside.at(32, 20, 0), 1.0f);
  EXPECT_EQ(s.segments.at(0, 0, 0), 0.0f);
  EXPECT_EQ(s.segments.at(20, 20, 0), 1.0f);
}

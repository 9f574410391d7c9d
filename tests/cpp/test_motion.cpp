#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tempera/engine/error.hpp"
#include "tempera/engine/motion.hpp"

using namespace tempera;

namespace {

// A 6x6 square over a static background, moving right by 3 px per frame:
// at frame f it covers x in [6 + 3f, 12 + 3f), y in [3, 9).
constexpr int kW = 24, kH = 12, kStep = 3;
bool in_square(int x, int y, int frame) { return x >= 6 + kStep * frame && x < 12 + kStep * frame && y >= 3 && y < 9; }

// Rendered velocities: the square carries (3, 0) in both V+ and V- (its
// displacement between consecutive frames), the background (0, 0).
Image velocity(int frame) {
  Image v(kW, kH, 2);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (in_square(x, y, frame)) v.at(x, y, 0) = float(kStep);
  return v;
}

}  // namespace

TEST(Motion, BackwardOcclusionMarksTheRevealedBackground) {
  // V+ and V- of this scene coincide per frame: frame 0 is t-1, frame 1 is t.
  Image chi = occlusion_backward(velocity(1).view(), velocity(0).view());
  ASSERT_EQ(chi.channels(), 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      // Behind the square's trailing edge: covered at t-1, visible at t.
      const bool revealed = in_square(x, y, 0) && !in_square(x, y, 1);
      EXPECT_EQ(chi.at(x, y, 0), revealed ? 0.0f : 1.0f) << "x=" << x << " y=" << y;
    }
}

TEST(Motion, ForwardOcclusionMarksTheBackgroundAboutToBeCovered) {
  Image chi = occlusion_forward(velocity(1).view(), velocity(2).view());
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool covered_next = in_square(x, y, 2) && !in_square(x, y, 1);
      EXPECT_EQ(chi.at(x, y, 0), covered_next ? 0.0f : 1.0f) << "x=" << x << " y=" << y;
    }
}

TEST(Motion, PointsFromOutsideTheFrameAreOccluded) {
  Image v(8, 3, 2);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 8; ++x) v.at(x, y, 0) = 5.0f;  // uniform pan, consistent in both fields
  Image chi = occlusion_backward(v.view(), v.view());
  for (int x = 0; x < 8; ++x) EXPECT_EQ(chi.at(x, 1, 0), x >= 5 ? 1.0f : 0.0f) << "x=" << x;
}

TEST(Motion, EpsilonIsTheSquaredTolerance) {
  Image here(4, 4, 2), there(4, 4, 2, 1.0f);  // differ by (1, 1): squared norm 2
  EXPECT_EQ(occlusion_backward(here.view(), there.view(), 2.0f).at(2, 2, 0), 0.0f);
  EXPECT_EQ(occlusion_backward(here.view(), there.view(), 2.01f).at(2, 2, 0), 1.0f);
}

TEST(Motion, WarpBackwardUndoesAnIntegerShift) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Image previous(20, 16, 3), v(20, 16, 2);
  for (int i = 0; i < 20 * 16 * 3; ++i) previous.data()[i] = u(rng);
  for (int i = 0; i < 20 * 16; ++i) v.data()[2 * i] = 3.0f, v.data()[2 * i + 1] = 2.0f;
  Image current = warp_backward(previous.view(), v.view());
  ASSERT_EQ(current.channels(), 3);
  for (int y = 2; y < 16; ++y)
    for (int x = 3; x < 20; ++x)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(current.at(x, y, c), previous.at(x - 3, y - 2, c), 1e-5f);
}

TEST(Motion, WarpBackwardIsBilinearForFractionalShifts) {
  // Bilinear interpolation reproduces a linear ramp exactly.
  Image previous(16, 12, 2), v(16, 12, 2);
  auto ramp = [](float x, float y, int c) { return 0.1f * x + 0.05f * y + float(c); };
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 16; ++x) {
      for (int c = 0; c < 2; ++c) previous.at(x, y, c) = ramp(float(x), float(y), c);
      v.at(x, y, 0) = 2.5f;
      v.at(x, y, 1) = -1.25f;
    }
  Image current = warp_backward(previous.view(), v.view());
  for (int y = 0; y < 10; ++y)
    for (int x = 3; x < 16; ++x)
      for (int c = 0; c < 2; ++c) EXPECT_NEAR(current.at(x, y, c), ramp(x - 2.5f, y + 1.25f, c), 1e-5f);
  // Beyond the border the edge pixels are repeated.
  EXPECT_NEAR(current.at(0, 0, 0), previous.at(0, 1, 0) + 0.25f * 0.05f, 1e-5f);
}

TEST(Motion, RejectsBadInputs) {
  Image v(8, 6, 2), small(8, 5, 2), three(8, 6, 3), image(8, 6, 4);
  EXPECT_THROW(occlusion_backward(v.view(), small.view()), ValueError);
  EXPECT_THROW(occlusion_forward(v.view(), small.view()), ValueError);
  EXPECT_THROW(warp_backward(image.view(), small.view()), ValueError);
  EXPECT_THROW(occlusion_backward(v.view(), three.view()), ValueError);
  EXPECT_THROW(warp_backward(image.view(), three.view()), ValueError);
  EXPECT_THROW(occlusion_backward(v.view(), v.view(), 0.0f), ValueError);
  EXPECT_THROW(occlusion_forward(v.view(), v.view(), -1.0f), ValueError);
  EXPECT_THROW(occlusion_forward(v.view(), v.view(), std::nanf("")), ValueError);
  EXPECT_THROW(occlusion_backward(ImageView{}, v.view()), ValueError);
  Image nan = v;
  nan.at(4, 2, 1) = std::nanf("");
  EXPECT_THROW(occlusion_backward(nan.view(), v.view()), ValueError);
  EXPECT_THROW(occlusion_forward(v.view(), nan.view()), ValueError);
  EXPECT_THROW(warp_backward(image.view(), nan.view()), ValueError);
  try {
    occlusion_backward(v.view(), small.view());
    FAIL();
  } catch (const ValueError& e) {
    EXPECT_NE(std::string(e.what()).find("v_plus_prev is 8x5"), std::string::npos) << e.what();
  }
}

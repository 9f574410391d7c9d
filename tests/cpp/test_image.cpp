#include <gtest/gtest.h>

#include <cmath>

#include "tempera/engine/error.hpp"
#include "tempera/engine/guide_stack.hpp"

using namespace tempera;

TEST(Image, RejectsNonPositiveSize) { EXPECT_THROW(Image(0, 3, 1), ValueError); }

TEST(Image, FiniteCheckNamesPixel) {
  Image img(4, 3, 2);
  img.at(3, 1, 1) = std::nanf("");
  try {
    require_finite(img.view(), "style");
    FAIL();
  } catch (const ValueError& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("style"), std::string::npos);
    EXPECT_NE(msg.find("x=3 y=1"), std::string::npos);
  }
}

TEST(Image, ExtractChannels) {
  Image img(2, 2, 3);
  img.at(1, 1, 2) = 5.0f;
  Image one = extract_channels(img.view(), 2, 1);
  EXPECT_EQ(one.channels(), 1);
  EXPECT_FLOAT_EQ(one.at(1, 1, 0), 5.0f);
  EXPECT_THROW(extract_channels(img.view(), 2, 2), ValueError);
}

TEST(GuideStack, RejectsMismatchedLayers) {
  Image a(8, 8, 3), b(10, 6, 3), c(8, 8, 1), small(4, 4, 3);
  GuideStack stack;
  stack.add("full", a.view(), b.view(), 2.0f);
  EXPECT_EQ(stack.total_channels(), 3);
  EXPECT_THROW(stack.add("bad-channels", a.view(), c.view()), ValueError);
  EXPECT_THROW(stack.add("bad-source-size", small.view(), b.view()), ValueError);
  EXPECT_THROW(stack.add("bad-weight", a.view(), b.view(), -1.0f), ValueError);
  stack.add("lde", a.view(), b.view(), 1.0f);
  EXPECT_EQ(stack.total_channels(), 6);
}

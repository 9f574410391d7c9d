// Mean voting: the fast loop for a few channels gives the general loop's
// floats, and both give the mean of the covering patches.
#include <gtest/gtest.h>

#include <random>

#include "tempera/engine/voting.hpp"
#include "test_inputs.hpp"

using namespace tempera;
using tempera::test_inputs::noise_texture;

namespace {

// The first `c` channels of `image`.
Image first_channels(const Image& image, int c) {
  Image out(image.width(), image.height(), c);
  for (std::size_t i = 0; i < image.pixel_count(); ++i)
    for (int k = 0; k < c; ++k) out.data()[i * c + k] = image.data()[i * image.channels() + k];
  return out;
}

}  // namespace

TEST(Voting, MeanOfAFewChannelsEqualsTheGeneralLoopAndTheMean) {
  const int sw = 30, sh = 26, tw = 21, th = 17, r = 2;
  const Image wide = noise_texture(sw, sh, 11, 4);  // more channels than the fast loop takes
  const Image narrow = first_channels(wide, 3);
  OffsetField field(tw, th);
  std::mt19937 rng(2);
  for (std::size_t i = 0; i < field.x.size(); ++i) field.x[i] = r + int(rng() % (sw - 2 * r)), field.y[i] = r + int(rng() % (sh - 2 * r));
  SearchConstraints cons;
  cons.target_active.assign(std::size_t(tw) * th, 1);
  std::vector<std::uint8_t> voters(cons.target_active.size(), 1);
  for (std::size_t i = 0; i < voters.size(); i += 7) voters[i] = 0;  // some patches do not vote
  cons.target_active[5] = 0;                                          // an inactive pixel keeps `previous`
  FeatureImage features;
  PatchSpace space;
  space.source = space.target = &features;
  space.radius = r;
  VoteParams params;
  params.voters = &voters;
  const Image previous(tw, th, 3, 0.25f);
  const Image fast = vote(narrow.view(), space, cons, field, previous.view(), params);
  const Image general = vote(wide.view(), space, cons, field, ImageView(), params);
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x) {
      const std::size_t i = std::size_t(y) * tw + x;
      for (int k = 0; k < 3; ++k) {
        if (!cons.target_active[i]) {
          EXPECT_EQ(fast.at(x, y, k), 0.25f);
          continue;
        }
        EXPECT_EQ(fast.at(x, y, k), general.at(x, y, k)) << x << "," << y;  // the same floats
        double sum = 0;
        int count = 0;
        for (int dy = -r; dy <= r; ++dy)
          for (int dx = -r; dx <= r; ++dx) {
            const int qx = x - dx, qy = y - dy;
            if (qx < 0 || qy < 0 || qx >= tw || qy >= th || !voters[std::size_t(qy) * tw + qx]) continue;
            const std::size_t q = std::size_t(qy) * tw + qx;
            sum += narrow.at(field.x[q] + dx, field.y[q] + dy, k);
            ++count;
          }
        EXPECT_NEAR(fast.at(x, y, k), sum / count, 1e-6) << x << "," << y;
      }
    }
}

// Mean voting: the fast loop for a few channels gives the general loop's
// floats, and both give the mean of the covering patches. The weighted mode:
// its AVX2 kernel picks what the scalar one picks, and both pick the mode.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <limits>
#include <cmath>
#include <random>

#include "tempera/engine/voting.hpp"
#include "tempera/engine/weighted_mode.hpp"
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

// The mode by its definition, in double, over every candidate (duplicates
// included): the scores of all candidates.
static std::vector<double> mode_scores(const std::vector<std::array<float, 3>>& v, double h) {
  std::vector<double> score(v.size(), 0.0);
  for (std::size_t j = 0; j < v.size(); ++j)
    for (std::size_t k = 0; k < v.size(); ++k) {
      if (k == j) continue;
      double d = 0;
      for (int ch = 0; ch < 3; ++ch) d += (double(v[j][ch]) - v[k][ch]) * (double(v[j][ch]) - v[k][ch]);
      score[j] += std::exp(-d / (h * h));
    }
  return score;
}

TEST(Voting, TheWeightedModeKernelsPickTheSameCandidateAndItIsTheMode) {
  const float h = 0.1f;
  std::mt19937 rng(5);
  ModeCandidates c;
  ModeScratch scalar, avx2;
  int checked = 0, unambiguous = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    // Up to 49 candidates (a 7x7 patch), drawn from a few colours so that many
    // repeat, as along a coherent field; some near each other, some far.
    const std::size_t n = 1 + rng() % 49, colours = 1 + rng() % 30;
    std::vector<std::array<float, 3>> palette(colours), v(n);
    for (auto& p : palette)
      for (float& x : p) x = float(rng() % 1000) / 1000.0f * (trial % 3 == 0 ? 1.0f : 0.3f);
    c.reset(3, 49);
    for (auto& x : v) {
      x = palette[rng() % colours];
      c.push(x.data());
    }
    const std::size_t pick = weighted_mode(c, h, scalar, FixedKernel::Scalar);
    ASSERT_LT(pick, n);
    if (fixed_kernel_supported(FixedKernel::Avx2)) {
      ASSERT_EQ(weighted_mode(c, h, avx2, FixedKernel::Avx2), pick) << "trial " << trial;
      ++checked;
    }
    const std::vector<double> score = mode_scores(v, h);
    const double best = *std::max_element(score.begin(), score.end());
    double runner_up = -1;  // the best score of a colour other than the best's
    for (std::size_t j = 0; j < n; ++j)
      if (v[j] != v[pick]) runner_up = std::max(runner_up, score[j]);
    EXPECT_NEAR(score[pick], best, 1e-4 * (1 + best)) << "trial " << trial;
    if (best - runner_up > 1e-3) ++unambiguous;
  }
  EXPECT_GT(unambiguous, 1000);  // the check above is not only among near-ties
  if (!fixed_kernel_supported(FixedKernel::Avx2)) GTEST_SKIP() << "no AVX2: only the scalar kernel was checked";
  EXPECT_EQ(checked, 3000);
}

TEST(Voting, TheWeightedModeKernelIsExpWithinTwoFloatSteps) {
  int worst = 0;
  for (float x = 0.0f; x <= 17.5f; x = std::nextafter(x + 1e-5f, 18.0f)) {
    const float exact = float(std::exp(-double(x)));
    const float k = mode_kernel(x);
    const int steps = std::abs(std::bit_cast<std::int32_t>(k) - std::bit_cast<std::int32_t>(exact));
    worst = std::max(worst, steps);
    ASSERT_LE(steps, 2) << "x = " << x << ": " << k << " against " << exact;
  }
  EXPECT_EQ(mode_kernel(17.6f), 0.0f);  // negligible against a score of at least 1
  EXPECT_EQ(mode_kernel(std::numeric_limits<float>::infinity()), 0.0f);
  EXPECT_EQ(mode_kernel(std::numeric_limits<float>::quiet_NaN()), 0.0f);
  EXPECT_EQ(mode_kernel(0.0f), 1.0f);
}

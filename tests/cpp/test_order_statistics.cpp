// The error budget's ranks are selected, not sorted: every selected value must
// be the one std::sort puts at that rank, so that the knee (and with it every
// assignment) is unchanged.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

#include "tempera/engine/order_statistics.hpp"
#include "tempera/engine/patch_usage.hpp"

using namespace tempera;

namespace {

void expect_selects_like_std_sort(const std::vector<float>& values) {
  std::vector<float> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const auto values_in = [&values](std::size_t begin, std::size_t end, auto&& f) {
    for (std::size_t i = begin; i < end; ++i) f(values[i]);
  };
  for (int threads : {1, 2, 3}) {
    const RadixSelect select(values_in, values.size(), threads);
    EXPECT_EQ(select.size(), values.size());
    if (!values.empty()) {
      EXPECT_EQ(select.values_at({values.size() - 1}).front(), sorted.back()) << threads;
    }
  }
  const RadixSelect select(values_in, values.size(), 2);
  // Every rank of a small set; of a large one, every 7th (a count table per
  // distinct prefix: all of 100 k ranks would take 100 MB).
  const std::size_t stride = values.size() > 5000 ? 7 : 1;
  std::vector<std::size_t> ranks;
  for (std::size_t r = 0; r < values.size(); r += stride) ranks.push_back(r);
  const std::vector<float> selected = select.values_at(ranks);
  ASSERT_EQ(selected.size(), ranks.size());
  for (std::size_t i = 0; i < ranks.size(); ++i) ASSERT_EQ(selected[i], sorted[ranks[i]]) << "rank " << ranks[i];
  // The knee from the subsample alone, as the budget takes it.
  const std::size_t n = values.size();
  EXPECT_EQ(error_knee(n, select.values_at(knee_sample_ranks(n))), error_knee(sorted));
  if (n > 0) {
    const std::vector<std::size_t> few = {n - 1, 0, n / 2, n / 2};  // any order, repeats
    const std::vector<float> picked = select.values_at(few);
    for (std::size_t i = 0; i < few.size(); ++i) EXPECT_EQ(picked[i], sorted[few[i]]);
  }
}

}  // namespace

TEST(OrderStatistics, SelectsRandomErrorsLikeStdSort) {
  std::mt19937 rng(7);
  std::exponential_distribution<float> error(3.0f);  // patch errors: many small, a long tail
  std::vector<float> values(100003);
  for (float& v : values) v = error(rng);
  expect_selects_like_std_sort(values);
}

TEST(OrderStatistics, SelectsTiedErrorsLikeStdSort) {
  // Few distinct values, each many times, with zeros and infinities, as
  // clipped or forced matches give.
  std::mt19937 rng(11);
  const float levels[] = {0.0f, 1e-6f, 0.25f, 0.25f, 3.0f, std::numeric_limits<float>::infinity()};
  std::vector<float> values(50000);
  for (float& v : values) v = levels[rng() % 6];
  expect_selects_like_std_sort(values);
}

TEST(OrderStatistics, SelectsNegativeValuesLikeStdSort) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(-1e3f, 1e3f);
  std::vector<float> values(4097);
  for (float& v : values) v = u(rng);
  values[0] = -std::numeric_limits<float>::infinity();
  values[1] = std::numeric_limits<float>::denorm_min();
  values[2] = -std::numeric_limits<float>::denorm_min();
  expect_selects_like_std_sort(values);
  expect_selects_like_std_sort({});
  expect_selects_like_std_sort({2.0f});
}

TEST(OrderStatistics, ARankPastTheSetIsAnError) {
  const std::vector<float> values = {3.0f, 1.0f, 2.0f};
  const auto values_in = [&values](std::size_t begin, std::size_t end, auto&& f) {
    for (std::size_t i = begin; i < end; ++i) f(values[i]);
  };
  const RadixSelect select(values_in, values.size(), 1);
  EXPECT_EQ(select.values_at({2}).front(), 3.0f);
  EXPECT_THROW(select.values_at({3}), ValueError);
}

TEST(OrderStatistics, KneeSamplesSpanTheCurve) {
  EXPECT_TRUE(knee_sample_ranks(7).empty());
  const auto few = knee_sample_ranks(8);
  EXPECT_EQ(few, (std::vector<std::size_t>{0, 1, 2, 3, 4, 5, 6, 7}));
  const auto many = knee_sample_ranks(1000003);
  ASSERT_EQ(many.size(), 1024u);
  EXPECT_EQ(many.front(), 0u);
  EXPECT_EQ(many.back(), 1000002u);
  EXPECT_TRUE(std::is_sorted(many.begin(), many.end()));
}

// The error budget's radix sort must order exactly like std::sort, so that the
// knee (and with it every assignment) is unchanged.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

#include "tempera/engine/patch_usage.hpp"
#include "tempera/engine/radix_sort.hpp"

using namespace tempera;

namespace {

void expect_sorts_like_std_sort(std::vector<float> values) {
  std::vector<float> expected = values;
  std::sort(expected.begin(), expected.end());
  std::vector<std::uint32_t> scratch;
  radix_sort(values, scratch);
  ASSERT_EQ(values.size(), expected.size());
  for (std::size_t i = 0; i < values.size(); ++i) ASSERT_EQ(values[i], expected[i]) << i;
  EXPECT_EQ(error_knee(values), error_knee(expected));
}

}  // namespace

TEST(RadixSort, OrdersRandomErrorsLikeStdSort) {
  std::mt19937 rng(7);
  std::exponential_distribution<float> error(3.0f);  // patch errors: many small, a long tail
  std::vector<float> values(100003);
  for (float& v : values) v = error(rng);
  expect_sorts_like_std_sort(values);
}

TEST(RadixSort, OrdersTiedErrorsLikeStdSort) {
  // Few distinct values, each many times, with zeros and infinities, as
  // clipped or forced matches give.
  std::mt19937 rng(11);
  const float levels[] = {0.0f, 1e-6f, 0.25f, 0.25f, 3.0f, std::numeric_limits<float>::infinity()};
  std::vector<float> values(50000);
  for (float& v : values) v = levels[rng() % 6];
  expect_sorts_like_std_sort(values);
}

TEST(RadixSort, OrdersNegativeValuesLikeStdSort) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(-1e3f, 1e3f);
  std::vector<float> values(4097);
  for (float& v : values) v = u(rng);
  values[0] = -std::numeric_limits<float>::infinity();
  values[1] = std::numeric_limits<float>::denorm_min();
  values[2] = -std::numeric_limits<float>::denorm_min();
  expect_sorts_like_std_sort(values);
  expect_sorts_like_std_sort({});
  expect_sorts_like_std_sort({2.0f});
}

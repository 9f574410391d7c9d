// The valid sources of a segment, kept as runs of consecutive indices
// (patchmatch.hpp): the same k-th index as the plain list they replace.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "tempera/engine/patchmatch.hpp"

namespace tempera {

TEST(SearchConstraints, SourceRunsIndexLikeTheList) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<std::int32_t> list;
    SourceIndexRuns runs;
    const int keep_one_in = 1 + trial % 4;  // from whole rows to scattered indices
    for (std::int32_t i = 0; i < 5000; ++i)
      if (rng() % 7 != 0 && rng() % keep_one_in == 0) list.push_back(i), runs.push_back(i);
    ASSERT_EQ(runs.size(), list.size());
    for (std::size_t k = 0; k < list.size(); ++k) ASSERT_EQ(runs[k], list[k]) << "trial " << trial << " k " << k;
  }
  EXPECT_TRUE(SourceIndexRuns().empty());
}

// An exemplar's margin-inset rows are one run a row: little memory.
TEST(SearchConstraints, ValidSourcesOfAnExemplarAreFound) {
  SearchConstraints cons;
  const int w = 40, h = 30, margin = 2;
  cons.source_valid.assign(std::size_t(w) * h, 0);
  std::vector<std::int32_t> expected;
  for (int y = margin; y < h - margin; ++y)
    for (int x = margin; x < w - margin; ++x) {
      cons.source_valid[std::size_t(y) * w + x] = 1;
      expected.push_back(y * w + x);
    }
  cons.target_active.assign(100, 1);
  cons.finalize();
  ASSERT_EQ(cons.valid_by_segment.size(), 1u);
  ASSERT_EQ(cons.valid_by_segment[0].size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) ASSERT_EQ(cons.valid_by_segment[0][k], expected[k]);
}

}  // namespace tempera

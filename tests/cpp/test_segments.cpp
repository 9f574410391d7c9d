// The job core's segment unit (app/segments.hpp): the one rule that cuts a
// shot at its keys, used by the coherent method's job and the farm planner.
#include <gtest/gtest.h>

#include "tempera/app/segments.hpp"
#include "tempera/engine/error.hpp"

using namespace tempera;

namespace {

std::vector<int> range(int first, int last) {
  std::vector<int> out;
  for (int f = first; f <= last; ++f) out.push_back(f);
  return out;
}

}  // namespace

TEST(Segments, KeysCutTheShotAndEachFrameHasOneWriter) {
  const auto segments = key_segments(range(1, 10), {7, 4, 4, 1, 10, 12});  // unsorted, repeated, at the ends
  ASSERT_EQ(segments.size(), 3u);
  EXPECT_EQ(segments[0].first, 1);
  EXPECT_EQ(segments[0].last, 4);
  EXPECT_EQ(segments[1].first, 4);
  EXPECT_EQ(segments[1].last, 7);
  EXPECT_EQ(segments[2].first, 7);
  EXPECT_EQ(segments[2].last, 10);
  std::vector<int> written;  // a shared key is written by the segment that starts there
  for (const Segment& s : segments) written.insert(written.end(), s.writes.begin(), s.writes.end());
  EXPECT_EQ(written, range(1, 10));
}

TEST(Segments, AShotWithoutInnerKeysIsOneSegment) {
  const auto whole = key_segments(range(5, 9), {});
  ASSERT_EQ(whole.size(), 1u);
  EXPECT_EQ(whole[0].first, 5);
  EXPECT_EQ(whole[0].last, 9);
  EXPECT_EQ(whole[0].writes, range(5, 9));
  const auto one = key_segments({3}, {3});
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].writes, std::vector<int>{3});
  EXPECT_THROW(key_segments({}, {}), ValueError);
}

TEST(Segments, SelectingOneNamesTheShotsSegmentsWhenItIsNotOne) {
  const auto segments = key_segments(range(1, 10), {4});
  EXPECT_EQ(select_segments(segments, std::nullopt), (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(select_segments(segments, std::make_pair(4, 10)), std::vector<std::size_t>{1});
  try {
    select_segments(segments, std::make_pair(1, 10));
    FAIL() << "1-10 is not a segment";
  } catch (const ValueError& e) {
    EXPECT_NE(std::string(e.what()).find("(1-4, 4-10; they run from key to key)"), std::string::npos) << e.what();
  }
}

// PatchMatch's random search within search_radius (PatchMatchParams,
// SynthesisOptions::search_radius): after a search's first sweep, a pixel
// with no neighbours to propagate from moves at most the radius in a sweep;
// the first sweep, and any sweep without a radius, jump across the exemplar.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>

#include "tempera/engine/patchmatch.hpp"
#include "test_inputs.hpp"

using namespace tempera;
using tempera::test_inputs::inner_sources;
using tempera::test_inputs::random_features;

namespace {

// How far (per axis, the larger) one sweep (the search's `sweep`th) moves
// the match of a lone target pixel that starts at (100, 75), over `seeds`
// seeds: the widest move.
int widest_move(int radius, int sweep, int seeds) {
  const int w = 200, h = 150;
  const FeatureImage s = random_features(w, h, 3, 1), t = random_features(1, 1, 3, 2);
  PatchSpace space;
  space.source = &s, space.target = &t;
  const SearchConstraints cons = inner_sources(w, h, 2, 1);
  int widest = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    OffsetField field(1, 1);
    field.x[0] = 100, field.y[0] = 75;
    refresh_distances(space, cons, field, 1);
    const float before = field.dist[0];
    PatchMatchParams pm;
    pm.iterations = 1, pm.first_iteration = sweep, pm.seed = std::uint64_t(seed), pm.threads = 1;
    pm.search_radius = radius;
    patchmatch(space, cons, field, pm, 0);
    EXPECT_LE(field.dist[0], before);
    widest = std::max({widest, std::abs(field.x[0] - 100), std::abs(field.y[0] - 75)});
  }
  return widest;
}

}  // namespace

TEST(SearchRadius, SweepsAfterTheFirstMoveAMatchAtMostTheRadius) {
  EXPECT_LE(widest_move(8, 1, 60), 8);
  EXPECT_LE(widest_move(8, 3, 60), 8);
  EXPECT_GT(widest_move(8, 1, 60), 0);  // it did search
  EXPECT_GT(widest_move(8, 0, 60), 8);  // the first sweep reaches the whole exemplar
  EXPECT_GT(widest_move(0, 1, 60), 8);  // 0: the whole exemplar in every sweep
}

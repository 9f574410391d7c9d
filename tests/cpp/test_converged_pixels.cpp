// Converged pixels (converged_pixels.hpp): which target pixels the forward
// search skips in the next EM iteration, that PatchMatch leaves them alone,
// and that the engine skips some and still lowers the energy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "tempera/engine/converged_pixels.hpp"
#include "tempera/engine/patchmatch.hpp"
#include "tempera/engine/synthesis.hpp"
#include "test_inputs.hpp"

using namespace tempera;
using tempera::test_inputs::inner_sources;
using tempera::test_inputs::noise_texture;
using tempera::test_inputs::random_features;

namespace {

OffsetField random_offsets(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  OffsetField f(w, h);
  for (std::size_t i = 0; i < f.x.size(); ++i) f.x[i] = int(rng() % 50), f.y[i] = int(rng() % 50);
  return f;
}

std::size_t count(const std::vector<std::uint8_t>& v) { return std::size_t(std::count(v.begin(), v.end(), 1)); }

}  // namespace

TEST(ConvergedPixels, OnlyChangedMatchesTheirNeighboursAndPatchesAreSearched) {
  const int w = 12, h = 10, r = 2;
  OffsetField field = random_offsets(w, h, 1);
  const std::vector<std::uint32_t> before = match_fingerprints(field);
  std::vector<std::uint8_t> active(std::size_t(w) * h, 1), unchanged(active.size(), 0), moved;
  auto search = [&](const std::vector<std::uint8_t>& image_changed) {
    return pixels_to_search(w, h, moved, image_changed, r, active);
  };
  mark_moved(field, before, moved);
  EXPECT_EQ(count(search(unchanged)), 0u);

  field.x[field.index(6, 5)] += 1;  // a moved match: it and its 4 neighbours
  mark_moved(field, before, moved);
  field.x[field.index(6, 5)] -= 1;  // put back (by the budget): still moved in this iteration
  mark_moved(field, before, moved);
  std::vector<std::uint8_t> s = search(unchanged);
  EXPECT_EQ(count(s), 5u);
  for (auto [x, y] : {std::pair{6, 5}, {5, 5}, {7, 5}, {6, 4}, {6, 6}}) EXPECT_TRUE(s[field.index(x, y)]);
  moved.assign(moved.size(), 0);
  field.rx[field.index(0, 0)] = 0.25f;  // a moved remainder counts as well (corner: 3 pixels)
  mark_moved(field, before, moved);
  EXPECT_EQ(count(search(unchanged)), 3u);
  moved.assign(moved.size(), 0);

  std::vector<std::uint8_t> changed = unchanged;  // a changed B' pixel: every patch that holds it
  changed[field.index(8, 2)] = 1;
  s = search(changed);
  EXPECT_EQ(count(s), 5u * 5u);  // x 6..10, y 0..4
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      EXPECT_EQ(s[field.index(x, y)], std::abs(x - 8) <= r && y <= 4) << x << "," << y;
  active[field.index(8, 2)] = 0;  // inactive pixels are never searched
  EXPECT_FALSE(search(changed)[field.index(8, 2)]);
}

TEST(ConvergedPixels, ChangesBelowOneStepAreUnchanged) {
  Image a(3, 1, 2, 0.5f), b = a;
  b.at(1, 0, 1) = 0.5f + 0.5f * kConvergedChange;
  b.at(2, 0, 0) = 0.5f - 2.0f * kConvergedChange;
  EXPECT_EQ(changed_pixels(a.view(), b.view()), (std::vector<std::uint8_t>{0, 0, 1}));
}

TEST(ConvergedPixels, PatchMatchLeavesUnsearchedPixelsAlone) {
  const int w = 40, h = 30, channels = 3;
  const FeatureImage s = random_features(w, h, channels, 1), t = random_features(w, h, channels, 2);
  PatchSpace space;
  space.source = &s, space.target = &t;
  const SearchConstraints cons = inner_sources(w, h, 2, std::size_t(w) * h);
  OffsetField start;
  random_field(space, cons, start, 5, 2);
  std::vector<std::uint8_t> searched(start.x.size(), 0);
  for (std::size_t i = 0; i < searched.size(); ++i) searched[i] = (i / 7) % 2;  // runs of 7 on, 7 off
  OffsetField field = start;
  PatchMatchParams pm;
  pm.iterations = 2, pm.seed = 5, pm.threads = 2;
  pm.searched = &searched;
  patchmatch(space, cons, field, pm, 1);
  double before = 0, after = 0;
  std::size_t improved = 0;
  for (std::size_t i = 0; i < searched.size(); ++i) {
    if (!searched[i]) {
      EXPECT_EQ(field.x[i], start.x[i]) << i;
      EXPECT_EQ(field.y[i], start.y[i]) << i;
      EXPECT_EQ(field.dist[i], start.dist[i]) << i;
      continue;
    }
    before += start.dist[i], after += field.dist[i];
    improved += field.dist[i] < start.dist[i];
  }
  EXPECT_LT(after, 0.8 * before);  // the searched pixels are still improved
  EXPECT_GT(improved, searched.size() / 4);
}

// The engine skips converged pixels at the finest level past the first EM
// iteration and still lowers the energy; switched off it skips none.
TEST(ConvergedPixels, TheEngineSkipsSomeAndTheEnergyStillDrops) {
  const int w = 64, h = 48;
  // Hatching: ink strokes whose density follows a gradient (as the bench's
  // painted exemplar): B' settles in most places after a few iterations.
  Image style(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        style.at(x, y, c) = std::sin(0.9f * float(x + y)) > 2.0f * float(y) / h - 1.0f ? 0.1f : 0.9f + 0.03f * c;
  Image sg(w, h, 2), tg(56, 56, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) sg.at(x, y, 0) = float(x) / w, sg.at(x, y, 1) = float(y) / h;
  for (int y = 0; y < 56; ++y)
    for (int x = 0; x < 56; ++x)  // a warped version of the source guide
      tg.at(x, y, 0) = 0.5f + 0.4f * std::sin(float(y) / 9.0f), tg.at(x, y, 1) = float(x) / 56;
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("g", sg.view(), tg.view(), 2.0f);
  for (PatchUsage usage : {PatchUsage::None, PatchUsage::Budget}) {
    SynthesisOptions off;
    off.skip_converged = false;
    off.em_tolerance = 0;  // all 6 iterations: the count below
    off.threads = 2;
    off.usage = usage;
    SynthesisOptions on = off, on1 = off;
    on.skip_converged = on1.skip_converged = true;
    on1.threads = 1;
    const SynthesisResult a = synthesize(in, on), b = synthesize(in, off), a1 = synthesize(in, on1);
    // Deterministic for any thread count, as the full search.
    EXPECT_TRUE(std::equal(a.image.data(), a.image.data() + a.image.pixel_count() * 3, a1.image.data())) << int(usage);
    const LevelStats& finest = a.levels.back();
    const std::size_t searches = std::size_t(finest.width) * finest.height * 6 * 2;  // 6 EM x 2 sweeps
    // The error budget's reversed retrieval reassigns many pixels of so small
    // a frame every iteration (those are searched again): fewer skips there.
    EXPECT_GT(finest.converged_skips, usage == PatchUsage::None ? searches / 10 : searches / 100) << int(usage);
    EXPECT_LT(finest.converged_skips, searches * 5 / 6) << int(usage);  // never in the first EM iteration
    EXPECT_LT(finest.energy.back(), 0.9 * finest.energy.front()) << int(usage);
    for (const LevelStats& l : b.levels) EXPECT_EQ(l.converged_skips, 0u) << l.width;
    // Only the finest level skips: a coarser level's losses would compound.
    for (std::size_t k = 0; k + 1 < a.levels.size(); ++k) EXPECT_EQ(a.levels[k].converged_skips, 0u) << k;
    // The skipped searches cost little: the final energy stays near the full search's.
    EXPECT_LT(finest.energy.back(), 1.05 * b.levels.back().energy.back()) << int(usage);
  }
}

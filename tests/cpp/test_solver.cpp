// Engine v2: the level-by-level solver, sub-pixel offset fields, the source
// set, energy terms, hard constraints and output modes. Each test fails when
// its feature is switched off or wrong.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <random>

#include "tempera/engine/error.hpp"
#include "tempera/engine/solver.hpp"
#include "tempera/engine/synthesis.hpp"

using namespace tempera;

namespace {

// Smooth random texture: noise blurred by a few box passes, so patches are
// distinct but neighbours correlate (like paint).
Image smooth_noise(int w, int h, int c, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Image img(w, h, c);
  for (std::size_t i = 0; i < img.pixel_count() * c; ++i) img.data()[i] = u(rng);
  for (int pass = 0; pass < 2; ++pass) {
    Image out(w, h, c);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int k = 0; k < c; ++k) {
          float s = 0;
          int n = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int xx = std::clamp(x + dx, 0, w - 1), yy = std::clamp(y + dy, 0, h - 1);
              s += img.at(xx, yy, k), ++n;
            }
          out.at(x, y, k) = s / n;
        }
    img = std::move(out);
  }
  return img;
}

Image coordinate_guide(int w, int h) {
  Image g(w, h, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) g.at(x, y, 0) = float(x) / w, g.at(x, y, 1) = float(y) / h;
  return g;
}

// Horizontal shift of b against a (integer part by search, sub-pixel by a
// parabola through the best three), over the interior rows and columns.
double horizontal_shift(const Image& a, const Image& b, int max_shift, int border) {
  auto error = [&](int s) {
    double sum = 0;
    int n = 0;
    for (int y = border; y < a.height() - border; ++y)
      for (int x = border; x < a.width() - border; ++x)
        for (int c = 0; c < a.channels(); ++c, ++n) {
          const double d = double(b.at(x, y, c)) - a.at(x - s, y, c);
          sum += d * d;
        }
    return sum / n;
  };
  int best = 0;
  for (int s = -max_shift; s <= max_shift; ++s)
    if (error(s) < error(best)) best = s;
  const double em = error(best - 1), e0 = error(best), ep = error(best + 1);
  const double denom = em - 2 * e0 + ep;
  return best + (denom > 0 ? 0.5 * (em - ep) / denom : 0.0);
}

SynthesisOptions options(PatchUsage usage, int threads = 2) {
  SynthesisOptions o;
  o.usage = usage;
  o.threads = threads;
  return o;
}

}  // namespace

TEST(Solver, SynthesizeEqualsDrivingTheSolverLevelByLevel) {
  const Image style = smooth_noise(64, 48, 3, 1), sg = coordinate_guide(64, 48), tg = coordinate_guide(56, 40);
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("coords", sg.view(), tg.view(), 2.0f);
  const SynthesisOptions opt = options(PatchUsage::Budget);
  const SynthesisResult whole = synthesize(in, opt);
  const Solver solver(in, opt);
  LevelResult r = solver.solve_level(solver.coarsest(), {});
  for (int l = solver.coarsest() - 1; l >= 0; --l) {
    const OffsetField up = solver.resample(r.field, l + 1, l);
    r = solver.solve_level(l, {&up});
  }
  ASSERT_EQ(r.image.pixel_count(), whole.image.pixel_count());
  for (std::size_t i = 0; i < r.image.pixel_count() * 3; ++i) ASSERT_EQ(r.image.data()[i], whole.image.data()[i]);
}

// synthesize()'s memory saving: a level's last solve frees its pyramids (a
// second solve or energy() of it is refused, sizes and resampling still
// work), and a handed-over start field is moved, not copied, with the same
// output as the copied one.
TEST(Solver, LastUseFreesTheLevelAndTakeFieldMovesTheStart) {
  const Image style = smooth_noise(64, 48, 3, 3), sg = coordinate_guide(64, 48), tg = coordinate_guide(56, 40);
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("coords", sg.view(), tg.view(), 2.0f);
  const SynthesisOptions opt = options(PatchUsage::Budget);
  const Solver kept(in, opt), freed(in, opt);
  const int c = kept.coarsest();
  const LevelResult coarse = kept.solve_level(c, {});
  OffsetField up = kept.resample(coarse.field, c, c - 1);
  const LevelResult copied = kept.solve_level(c - 1, {&up});
  LevelStart start;
  start.take_field = &up;
  start.last_use = true;
  const LevelResult moved = freed.solve_level(c - 1, start);
  EXPECT_TRUE(up.x.empty());
  ASSERT_EQ(moved.image.pixel_count(), copied.image.pixel_count());
  for (std::size_t i = 0; i < moved.image.pixel_count() * 3; ++i) ASSERT_EQ(moved.image.data()[i], copied.image.data()[i]);
  EXPECT_THROW(freed.solve_level(c - 1, {}), ValueError);
  EXPECT_THROW(freed.energy(c - 1, moved.field, moved.image), ValueError);
  EXPECT_EQ(freed.target_width(c - 1), kept.target_width(c - 1));
  const OffsetField down = freed.resample(moved.field, c - 1, c);
  EXPECT_EQ(down.width, freed.target_width(c));
  EXPECT_NO_THROW(kept.solve_level(c - 1, {&copied.field}));  // without last_use: any order, again
}

// em_tolerance: the finest level stops after the first EM iteration that
// lowers the energy by less than that fraction, with the energies of the full
// run up to there (the iterations it runs are the same); coarser levels run
// all of theirs. Off (0), it runs every iteration.
TEST(Solver, TheFinestLevelStopsOnceAnIterationGainsLittle) {
  const Image style = smooth_noise(96, 72, 3, 5), sg = coordinate_guide(96, 72), tg = coordinate_guide(88, 64);
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("coords", sg.view(), tg.view(), 2.0f);
  SynthesisOptions opt = options(PatchUsage::None);
  opt.em_tolerance = 0;
  const SynthesisResult full = synthesize(in, opt);
  const std::vector<double>& e = full.levels.back().energy;
  ASSERT_EQ(int(e.size()), opt.em_iterations);
  opt.em_tolerance = 0.05;
  std::size_t expected = e.size();
  for (std::size_t i = 1; i < e.size(); ++i)
    if (e[i] <= e[i - 1] && e[i - 1] - e[i] < opt.em_tolerance * e[i - 1]) {
      expected = i + 1;
      break;
    }
  ASSERT_LT(expected, e.size()) << "the problem must settle before its last iteration";
  const SynthesisResult early = synthesize(in, opt);
  const std::vector<double>& stopped = early.levels.back().energy;
  ASSERT_EQ(stopped.size(), expected);
  for (std::size_t i = 0; i < expected; ++i) EXPECT_EQ(stopped[i], e[i]);
  for (std::size_t l = 0; l + 1 < early.levels.size(); ++l)
    EXPECT_EQ(int(early.levels[l].energy.size()), opt.em_iterations) << "level " << l;
  EXPECT_LT(stopped.back(), e.back() * 1.10);
}

TEST(Solver, WarmStartFromItsOwnFieldIsNoWorseInHalfTheTime) {
  const Image style = smooth_noise(96, 72, 3, 2), sg = coordinate_guide(96, 72), tg = coordinate_guide(88, 64);
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("coords", sg.view(), tg.view(), 2.0f);
  SynthesisOptions opt = options(PatchUsage::None);
  const Solver solver(in, opt);
  const auto t0 = std::chrono::steady_clock::now();
  LevelResult cold = solver.solve_level(solver.coarsest(), {});
  for (int l = solver.coarsest() - 1; l >= 0; --l) {
    const OffsetField up = solver.resample(cold.field, l + 1, l);
    cold = solver.solve_level(l, {&up});
  }
  const double cold_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cold_energy = solver.energy(0, cold.field, cold.image);
  SynthesisOptions warm_opt = opt;
  warm_opt.em_iterations = 1;  // a warm start needs one round to settle
  const Solver warm_solver(in, warm_opt);
  const auto t1 = std::chrono::steady_clock::now();
  const LevelResult warm = warm_solver.solve_level(0, {&cold.field, &cold.image});
  const double warm_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  EXPECT_LE(solver.energy(0, warm.field, warm.image), cold_energy * (1 + 1e-6));
  EXPECT_LE(warm_seconds, 0.5 * cold_seconds);
}

// A warm start's restarted pixels (hidden in the previous frame) are matched
// on the guides alone, as a cold start's coarsest level is, and not left at
// random matches whose vote is noise: with no EM search at all, a band of
// restarted pixels lands where the coordinate guide says (random matches:
// about a third of the frame away); the held pixels keep their matches.
TEST(Solver, WarmStartMatchesRestartedPixelsOnTheGuides) {
  const int w = 80, h = 40;
  const Image style = smooth_noise(w, h, 3, 7);
  const Image guide = coordinate_guide(w, h);
  SynthesisInput in;
  in.style = style.view();
  in.target_width = w;
  in.target_height = h;
  in.guides.add("coords", guide.view(), guide.view(), 2.0f);
  SynthesisOptions opt = options(PatchUsage::None);
  const SynthesisResult first = synthesize(in, opt);
  opt.em_iterations = 1;
  opt.pm_iterations = 0;
  Image visible(w, h, 1, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 30; x < 40; ++x) visible.at(x, y, 0) = 0.0f;
  const Image still(w, h, 2, 0.0f);
  const SynthesisResult warm = synthesize_warm(in, opt, first.field, still.view(), visible.view());
  double off_guide = 0;
  int restarted = 0;
  for (int y = 4; y < h - 4; ++y)
    for (int x = 30; x < 40; ++x, ++restarted) {
      const std::size_t i = warm.field.index(x, y);
      off_guide += std::abs(warm.field.position_x(i) - x) + std::abs(warm.field.position_y(i) - y);
    }
  EXPECT_LT(off_guide / restarted, 3.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (x >= 30 && x < 40) continue;
      const std::size_t i = warm.field.index(x, y);
      ASSERT_EQ(warm.field.x[i], first.field.x[i]);
      ASSERT_EQ(warm.field.y[i], first.field.y[i]);
    }
}

// synthesize_warm (issue 32): the finest level alone, started from the
// previous frame's field moved along the motion. With no search the output is
// the previous frame's carried 3 px to the right; the field's size is checked.
TEST(Solver, SynthesizeWarmStartsFromThePreviousFieldAdvected) {
  const int w = 80, h = 40;
  const Image style = smooth_noise(w, h, 3, 5);
  SynthesisInput in;
  in.style = style.view();
  in.target_width = w;
  in.target_height = h;
  SynthesisOptions opt = options(PatchUsage::None);
  opt.output = OutputMode::Centre;
  const SynthesisResult first = synthesize(in, opt);
  Image velocity(w, h, 2, 0.0f);
  for (std::size_t i = 0; i < velocity.pixel_count(); ++i) velocity.data()[2 * i] = 3.0f;
  opt.em_iterations = 1;
  opt.pm_iterations = 0;
  const SynthesisResult warm = synthesize_warm(in, opt, first.field, velocity.view());
  ASSERT_EQ(warm.levels.size(), 1u);
  EXPECT_EQ(warm.levels[0].width, w);
  EXPECT_NEAR(horizontal_shift(first.image, warm.image, 6, 8), 3.0, 0.1);
  const SynthesisResult cold = synthesize(in, opt);  // the same options from a cold start: no such shift
  EXPECT_GT(std::abs(horizontal_shift(first.image, cold.image, 6, 8) - 3.0), 1.0);
  EXPECT_THROW(synthesize_warm(in, opt, OffsetField(w - 1, h), velocity.view()), ValueError);
  // Pixels not visible in the previous frame (a band) restart at random; the others carry their match.
  Image visible(w, h, 1, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 30; x < 40; ++x) visible.at(x, y, 0) = 0.0f;
  const SynthesisResult restarted = synthesize_warm(in, opt, first.field, velocity.view(), visible.view());
  int carried_inside = 0, carried_outside = 0, outside = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 3; x < w; ++x) {
      const std::size_t i = restarted.field.index(x, y), p = first.field.index(x - 3, y);
      const bool carried = restarted.field.x[i] == first.field.x[p] && restarted.field.y[i] == first.field.y[p];
      if (x >= 30 && x < 40) carried_inside += carried;
      else carried_outside += carried, ++outside;
    }
  EXPECT_LT(carried_inside, h * 10 / 20);
  EXPECT_EQ(carried_outside, outside);
  EXPECT_THROW(synthesize_warm(in, opt, first.field, velocity.view(), Image(w, h - 1, 1).view()), ValueError);
  // A field through its positions image (what the jobs write) comes back the same.
  const OffsetField back = field_from_positions(field_positions(first.field).view());
  for (std::size_t i = 0; i < back.x.size(); ++i) {
    ASSERT_EQ(back.x[i], first.field.x[i]);
    ASSERT_EQ(back.ry[i], first.field.ry[i]);
  }
}

TEST(Solver, SubPixelMotionAccumulatesOverAdvection) {
  // 0.3 px per frame to the right for 10 frames moves the output 3 px; with
  // integer offsets each step would round back to where it was.
  const int w = 80, h = 40;
  const Image style = smooth_noise(w, h, 3, 3);
  SynthesisInput in;
  in.style = style.view();
  in.target_width = w;
  in.target_height = h;
  SynthesisOptions opt = options(PatchUsage::None);
  opt.levels = 1;
  opt.em_iterations = 1;
  opt.pm_iterations = 0;
  opt.output = OutputMode::Centre;
  const Solver solver(in, opt);
  OffsetField field(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) field.set_position(field.index(x, y), float(x), float(y));
  const Image first = solver.solve_level(0, {&field}).image;
  Image velocity(w, h, 2);
  for (std::size_t i = 0; i < velocity.pixel_count(); ++i) velocity.data()[2 * i] = 0.3f;
  for (int f = 0; f < 10; ++f) field = solver.advect(field, 0, velocity.view());
  const Image last = solver.solve_level(0, {&field}).image;
  EXPECT_NEAR(horizontal_shift(first, last, 6, 8), 3.0, 0.3);
}

TEST(Solver, ResampledFieldsKeepTheirSubPixelPart) {
  const Image style = smooth_noise(64, 64, 1, 4);
  SynthesisInput in;
  in.style = style.view();
  in.target_width = 64;
  in.target_height = 64;
  SynthesisOptions opt = options(PatchUsage::None);
  opt.levels = 2;
  const Solver solver(in, opt);
  OffsetField coarse(solver.target_width(1), solver.target_height(1));
  for (std::size_t i = 0; i < coarse.x.size(); ++i) coarse.set_position(i, 10.3f, 12.4f);
  const OffsetField fine = solver.resample(coarse, 1, 0);
  // (10.3, 12.4) at half size is (20.6, 24.8) plus each pixel's offset in its parent.
  EXPECT_NEAR(fine.position_x(fine.index(6, 6)), 20.6f, 1e-4);
  EXPECT_NEAR(fine.position_y(fine.index(7, 7)), 25.8f, 1e-4);
  const OffsetField back = solver.resample(fine, 0, 1);
  EXPECT_NEAR(back.position_x(back.index(3, 3)), 10.3f, 1e-4);
}

TEST(Solver, CentreLookupCopiesExemplarColoursOnly) {
  const int w = 64, h = 48;
  Image style(w, h, 3);
  const Image blobs = smooth_noise(w, h, 1, 5);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool ink = blobs.at(x, y, 0) > 0.5f;
      for (int c = 0; c < 3; ++c) style.at(x, y, c) = ink ? 0.1f * (c + 1) : 0.9f;
    }
  const Image sg = coordinate_guide(w, h), tg = smooth_noise(56, 40, 2, 6);
  auto exact_fraction = [&](OutputMode mode) {
    SynthesisInput in;
    in.style = style.view();
    in.guides.add("g", sg.view(), tg.view(), 1.0f);
    SynthesisOptions opt = options(PatchUsage::Budget);
    opt.output = mode;
    const Image out = synthesize(in, opt).image;
    std::size_t exact = 0;
    for (int y = 0; y < out.height(); ++y)
      for (int x = 0; x < out.width(); ++x) {
        const float* p = out.pixel(x, y);
        exact += (p[0] == 0.9f && p[1] == 0.9f && p[2] == 0.9f) || (p[0] == 0.1f && p[1] == 0.2f && p[2] == 0.3f);
      }
    return double(exact) / double(out.pixel_count());
  };
  EXPECT_GE(exact_fraction(OutputMode::Centre), 0.999);
  EXPECT_GE(exact_fraction(OutputMode::Random), 0.999);
  EXPECT_GE(exact_fraction(OutputMode::Mode), 0.999);
  EXPECT_LT(exact_fraction(OutputMode::Mean), 0.9);  // blending makes new colours
}

TEST(Solver, HardConstrainedPixelsKeepTheirValuesAndNeighboursContinueThem) {
  const int sw = 80, sh = 64, tw = 48, th = 40;
  const Image style = smooth_noise(sw, sh, 3, 7);
  Image mask(tw, th, 1), values(tw, th, 3), matches(tw, th, 3);
  const int ox = 17, oy = 11;  // the painted part is the exemplar shifted by (ox, oy)
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x) {
      mask.at(x, y, 0) = x < 20 ? 1.0f : 0.0f;
      for (int c = 0; c < 3; ++c) values.at(x, y, c) = style.at(x + ox, y + oy, c);
      matches.at(x, y, 0) = 0, matches.at(x, y, 1) = float(x + ox), matches.at(x, y, 2) = float(y + oy);
    }
  auto continued = [&](bool fixed, Image* out) {
    SynthesisInput in;
    in.style = style.view();
    in.target_width = tw;
    in.target_height = th;
    if (fixed) in.fixed = FixedPixels{mask.view(), values.view(), matches.view()};
    const SynthesisResult r = synthesize(in, options(PatchUsage::None));
    if (out) *out = r.image;
    int hits = 0, n = 0;
    for (int y = 3; y < th - 3; ++y)
      for (int x = 20; x < 23; ++x, ++n) {
        const ExemplarMatch m = r.match(x, y);
        hits += std::abs(m.x - (x + ox)) < 0.5f && std::abs(m.y - (y + oy)) < 0.5f;
      }
    return double(hits) / n;
  };
  Image out;
  EXPECT_GE(continued(true, &out), 0.9);
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < 20; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(out.at(x, y, c), values.at(x, y, c));
  EXPECT_LT(continued(false, nullptr), 0.2);
}

TEST(Solver, InjectedCandidatesAreTaken) {
  const Image style = smooth_noise(64, 64, 3, 8);
  Image target(40, 40, 3);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x)
      for (int c = 0; c < 3; ++c) target.at(x, y, c) = style.at(x + 12, y + 9, c);
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("copy", style.view(), target.view(), 4.0f);
  SynthesisOptions opt = options(PatchUsage::None);
  opt.levels = 1;
  opt.em_iterations = 1;
  opt.pm_iterations = 1;
  const Solver solver(in, opt);
  OffsetField start(40, 40);
  for (std::size_t i = 0; i < start.x.size(); ++i) start.set_position(i, 40, 40);  // all wrong
  CandidateList ribbons;
  ribbons.begin.push_back(0);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) {
      if ((x + y) % 7 == 0) ribbons.x.push_back(x + 12), ribbons.y.push_back(y + 9);
      ribbons.begin.push_back(std::uint32_t(ribbons.x.size()));
    }
  auto correct = [&](const CandidateList* c) {
    LevelStart from;
    from.field = &start;
    from.candidates = c;
    const LevelResult r = solver.solve_level(0, from);
    int ok = 0;
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 40; ++x) ok += r.field.x[r.field.index(x, y)] == x + 12 && r.field.y[r.field.index(x, y)] == y + 9;
    return ok / 1600.0;
  };
  EXPECT_GT(correct(&ribbons), correct(nullptr) + 0.3);
  EXPECT_GT(correct(&ribbons), 0.9);
}

TEST(Solver, VideoExemplarIsMatchedAtTheRightFrame) {
  // Six frames of a texture translating 3 px per frame, with the frame time
  // as a guide; the target is frame 3.
  const int w = 64, h = 40, frames = 6;
  const Image texture = smooth_noise(w + 3 * frames, h, 3, 9);
  std::vector<Image> style(frames), time_guide(frames);
  for (int k = 0; k < frames; ++k) {
    style[k] = Image(w, h, 3);
    time_guide[k] = Image(w, h, 1, float(k) / frames);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) style[k].at(x, y, c) = texture.at(x + 3 * k, y, c);
  }
  const Image target_time(48, 32, 1, 3.0f / frames);
  SynthesisInput in;
  in.style = style[0].view();
  in.sequence = 0;
  in.time = 0;
  in.guides.add("time", time_guide[0].view(), target_time.view(), 10.0f);
  for (int k = 1; k < frames; ++k) {
    Exemplar e;
    e.style = style[k].view();
    e.guides = {time_guide[k].view()};
    e.sequence = 0;
    e.time = k;
    in.exemplars.push_back(e);
  }
  const SynthesisResult r = synthesize(in, options(PatchUsage::None));
  int right = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 48; ++x) right += r.match(x, y).exemplar == 3;
  EXPECT_GE(right / double(48 * 32), 0.95);
}

TEST(Solver, HistogramTermBreaksUpHotspotsAtLittleEnergy) {
  // A repetitive exemplar (a tile repeated 6 x 4, with a little noise) and
  // flat guides: many patches fit equally, and plain nearest neighbours pile
  // onto a few of them.
  const int sw = 96, sh = 64, tw = 64, th = 48;
  std::mt19937 rng(10);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Image tile(16, 16, 3), style(sw, sh, 3);
  for (std::size_t i = 0; i < tile.pixel_count() * 3; ++i) tile.data()[i] = u(rng);
  for (int y = 0; y < sh; ++y)
    for (int x = 0; x < sw; ++x)
      for (int c = 0; c < 3; ++c) style.at(x, y, c) = tile.at(x % 16, y % 16, c) + 0.02f * u(rng);
  const Image sg(sw, sh, 1, 0.5f), tg(tw, th, 1, 0.5f);
  auto run = [&](PatchUsage usage, double& energy) {
    SynthesisInput in;
    in.style = style.view();
    in.guides.add("band", sg.view(), tg.view(), 1.0f);
    // Float features: the flat guides make this a test of near-ties, and
    // 12-bit rounding turns some into exact ties that spread plain nearest
    // neighbours by themselves (peak 5.0 instead of 6.0+).
    SynthesisOptions opt = options(usage);
    opt.feature_precision = FeaturePrecision::Float;
    // The full search as the baseline: skipping converged pixels leaves plain
    // nearest neighbours less time to pile up.
    opt.skip_converged = false;
    const SynthesisResult r = synthesize(in, opt);
    energy = r.levels.back().energy.back();
    // Blurred usage count, as the term sees it (sigma 1.5).
    std::vector<float> uses(std::size_t(sw) * sh, 0.0f);
    for (std::size_t i = 0; i < r.field.x.size(); ++i) uses[std::size_t(r.field.y[i]) * sw + r.field.x[i]] += 1;
    float peak = 0;
    for (int y = 3; y < sh - 3; ++y)
      for (int x = 3; x < sw - 3; ++x) {
        float s = 0, wsum = 0;
        for (int dy = -3; dy <= 3; ++dy)
          for (int dx = -3; dx <= 3; ++dx) {
            const float wgt = std::exp(-(dx * dx + dy * dy) / (2 * 1.5f * 1.5f));
            s += wgt * uses[std::size_t(y + dy) * sw + x + dx], wsum += wgt;
          }
        peak = std::max(peak, s / wsum);
      }
    return peak;
  };
  double e_none = 0, e_hist = 0, e_foot = 0;
  const float peak_none = run(PatchUsage::None, e_none), peak_hist = run(PatchUsage::Histogram, e_hist);
  EXPECT_LE(peak_hist * 2, peak_none);
  EXPECT_LE(e_hist, 1.1 * e_none);
  // Fluidymation's footprint count spreads them too.
  const float peak_foot = run(PatchUsage::Footprint, e_foot);
  EXPECT_LT(peak_foot * 1.5, peak_none);
  RecordProperty("peaks", std::to_string(peak_none) + " " + std::to_string(peak_hist) + " " + std::to_string(peak_foot));
}

TEST(Solver, SpatialCoherenceTermMakesTheFieldMoreCoherent) {
  const Image style = smooth_noise(80, 64, 3, 11), sg = smooth_noise(80, 64, 2, 12), tg = smooth_noise(56, 48, 2, 13);
  auto coherent_fraction = [&](bool term) {
    SynthesisInput in;
    in.style = style.view();
    in.guides.add("g", sg.view(), tg.view(), 1.0f);
    if (term) in.terms.push_back(make_spatial_coherence(0.02f, 3.0f));
    const SynthesisResult r = synthesize(in, options(PatchUsage::None));
    int same = 0, n = 0;
    for (int y = 0; y < r.field.height; ++y)
      for (int x = 1; x < r.field.width; ++x, ++n) {
        const std::size_t i = r.field.index(x, y), j = r.field.index(x - 1, y);
        same += r.field.x[i] == r.field.x[j] + 1 && r.field.y[i] == r.field.y[j];
      }
    return double(same) / n;
  };
  EXPECT_GT(coherent_fraction(true), coherent_fraction(false) + 0.1);
}

TEST(Solver, ReferenceStartsTheCoarsestLevel) {
  // Without guides, the result follows the reference's large shapes.
  const Image style = smooth_noise(64, 64, 1, 14);
  Image reference(48, 48, 1);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) reference.at(x, y, 0) = x < 24 ? 0.3f : 0.7f;
  SynthesisInput in;
  in.style = style.view();
  in.target_width = in.target_height = 48;
  in.reference = reference.view();
  const Image out = synthesize(in, options(PatchUsage::None)).image;
  double left = 0, right = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) (x < 24 ? left : right) += out.at(x, y, 0);
  EXPECT_LT(left, right);
}

TEST(Solver, LevelRatioAndBoxWidthsBuildAFinerPyramid) {
  const Image style = smooth_noise(120, 100, 3, 15), sg = coordinate_guide(120, 100), tg = coordinate_guide(100, 80);
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("g", sg.view(), tg.view());
  SynthesisOptions opt = options(PatchUsage::None);
  opt.level_ratio = 0.85;
  opt.level_box_widths = {1.0f, 1.5f, 2.0f};
  const Solver solver(in, opt);
  ASSERT_GE(solver.levels(), 4);
  EXPECT_EQ(solver.target_width(1), 85);
  EXPECT_EQ(solver.target_height(1), 68);
  const SynthesisResult r = synthesize(in, opt);
  EXPECT_EQ(r.image.width(), 100);
  EXPECT_GT(int(r.levels.size()), 4);
}

TEST(Solver, NewFeaturesAreIdenticalForAnyThreadCount) {
  const Image style = smooth_noise(64, 48, 3, 16), sg = coordinate_guide(64, 48), tg = coordinate_guide(56, 40);
  auto run = [&](int threads, PatchUsage usage, OutputMode mode, ColorSpace cs, float sigma) {
    SynthesisInput in;
    in.style = style.view();
    in.guides.add("g", sg.view(), tg.view());
    in.terms.push_back(make_spatial_coherence(0.01f, 3.0f));
    SynthesisOptions opt = options(usage, threads);
    opt.output = mode;
    opt.color_space = cs;
    opt.window_sigma = sigma;
    return synthesize(in, opt).image;
  };
  for (auto [usage, mode, cs, sigma] : {std::tuple{PatchUsage::Histogram, OutputMode::Random, ColorSpace::Lab, 2.0f},
                                         std::tuple{PatchUsage::Uniform, OutputMode::Mode, ColorSpace::Rgb, 0.0f}}) {
    const Image a = run(1, usage, mode, cs, sigma), b = run(2, usage, mode, cs, sigma);
    for (std::size_t i = 0; i < a.pixel_count() * 3; ++i) ASSERT_EQ(a.data()[i], b.data()[i]);
  }
}

TEST(Solver, BadInputNamesTheProblem) {
  const Image style = smooth_noise(32, 32, 3, 17), g = coordinate_guide(32, 32), small(20, 20, 3);
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("g", g.view(), g.view());
  Exemplar e;
  e.style = small.view();
  in.exemplars.push_back(e);
  try {
    synthesize(in, options(PatchUsage::None));
    FAIL();
  } catch (const ValueError& err) {
    EXPECT_NE(std::string(err.what()).find("exemplar 1 has 0 guides for 1 guide layers"), std::string::npos) << err.what();
  }
  in.exemplars.clear();
  SynthesisOptions opt = options(PatchUsage::None);
  opt.style_channel_weights = {1, 1};
  EXPECT_THROW(synthesize(in, opt), ValueError);
  opt = options(PatchUsage::None);
  opt.level_ratio = 2;
  EXPECT_THROW(synthesize(in, opt), ValueError);
  const Solver solver(in, options(PatchUsage::None));
  EXPECT_THROW(solver.solve_level(99, {}), ValueError);
  const OffsetField wrong(3, 3);
  EXPECT_THROW(solver.solve_level(0, {&wrong}), ValueError);
}

// The rigid-body method end to end on the generated exemplar: sub-sequences,
// Diff and its augmentation, the round trip through the residual,
// self-reproduction, the oracle, contacts and stitching (the tests).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "tempera/engine/error.hpp"
#include "tempera/methods/rigid/quadratic_fit.hpp"
#include "tempera/methods/rigid/rigid.hpp"
#include "tempera/methods/rigid/rigid_exemplar.hpp"
#include "tempera/methods/rigid/rigid_frame.hpp"
#include "tempera/methods/rigid/silhouette.hpp"

using namespace tempera;

namespace {

constexpr int W = 320, H = 200;

// The source: a ball thrown to the right, four bounces in 48 frames.
Track source_track() { return bouncing_ball({40, 50}, {4.5, 0}, 18, 1.2, 180, 0.6, 0.05, 48); }

Image alpha_of(const Image& rgba) {
  Image a(rgba.width(), rgba.height(), 1);
  for (std::size_t i = 0; i < a.pixel_count(); ++i) a.data()[i] = rgba.data()[4 * i + 3];
  return a;
}

// The drawing's region: everything the background's flood fill does not
// reach, the strokes included (filled_silhouette gives those >= 0.5 and the
// background <= 0.25).
Image solid(const Image& ink) {
  Image s = filled_silhouette(ink.view());
  for (std::size_t i = 0; i < s.pixel_count(); ++i) s.data()[i] = s.data()[i] > 0.4f ? 1.0f : 0.0f;
  return s;
}

// A fitted exemplar with its residuals, from the generator.
struct Fitted {
  RigidExemplar exemplar;
  std::vector<Image> drawings, residuals;
};

Fitted fit_exemplar(const Track& track, const ExemplarStyle& style) {
  Fitted out;
  out.exemplar.track = track;
  for (int f = 0; f < int(track.frames.size()); ++f) {
    const TrackFrame& tf = track.frames[std::size_t(f)];
    out.drawings.push_back(draw_exemplar_frame(track, f, style, W, H));
    const Image mask = proxy_mask(tf, style.shape, W, H);
    const ObjectFrame frame{tf.centre, tf.radius};
    const QuadraticMap D = fit_quadratic_map(mask.view(), alpha_of(out.drawings.back()).view(), frame);
    out.exemplar.maps.push_back(D);
    out.residuals.push_back(extract_residual(out.drawings.back().view(), D, frame));
  }
  return out;
}

const Fitted& ball() {
  static const Fitted fitted = fit_exemplar(source_track(), ExemplarStyle{});
  return fitted;
}

ResidualSource residuals_of(const Fitted& f) {
  return [&f](int, int frame) { return f.residuals[std::size_t(frame)].view(); };
}

double stretch_along(const QuadraticMap& D, Vec2 dir) {
  const auto J = jacobian(D, {0, 0});
  const double n = std::hypot(dir.x, dir.y);
  if (n < 1e-9) return 1;
  const double x = dir.x / n, y = dir.y / n;
  return std::hypot(J[0] * x + J[1] * y, J[2] * x + J[3] * y);
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const double ma = std::accumulate(a.begin(), a.end(), 0.0) / a.size();
  const double mb = std::accumulate(b.begin(), b.end(), 0.0) / b.size();
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sab += (a[i] - ma) * (b[i] - mb), saa += (a[i] - ma) * (a[i] - ma), sbb += (b[i] - mb) * (b[i] - mb);
  return sab / std::sqrt(saa * sbb);
}

// RMS distance (radius units) of the deformed unit circle from the circle:
// how visibly D deforms a disc. (D - I itself is not observable on a disc:
// its rotation and the direction x^2 + y^2 - 1 leave the outline alone.)
double outline_deviation(const QuadraticMap& D) {
  double sum = 0;
  for (int i = 0; i < 90; ++i) {
    const double t = 2 * 3.14159265358979 * i / 90;
    const Vec2 q = apply(D, {std::cos(t), std::sin(t)});
    const Vec2 c = apply(D, {0, 0});
    sum += std::pow(std::hypot(q.x - c.x, q.y - c.y) - 1, 2);
  }
  return std::sqrt(sum / 90);
}

int distance_to_event(const Track& t, int f) {
  int best = 1 << 30;
  for (const RigidEvent& e : t.events) best = std::min(best, std::abs(e.frame - f));
  return best;
}

}  // namespace

TEST(RigidTrack, BouncingBallHasItsBounces) {
  const Track t = source_track();
  ASSERT_EQ(t.events.size(), 4u);
  // The nearest frame to a bounce is within half a frame's fall of the floor.
  for (const RigidEvent& e : t.events) {
    const TrackFrame& f = t.frames[std::size_t(e.frame)];
    EXPECT_NEAR(f.centre.y, 180 - 18, 0.5 * std::abs(f.velocity.y) + 8) << "bounce at " << e.frame;
    EXPECT_LT(t.frames[std::size_t(e.frame)].centre.y, 180 - 18 + 1e-9);
  }
}

TEST(RigidSubSequences, CutAroundEventsWithOverlaps) {
  const Track t = source_track();
  const auto subs = cut_subsequences(t);
  ASSERT_EQ(subs.size(), t.events.size());
  EXPECT_EQ(subs.front().first, 0);
  EXPECT_EQ(subs.back().last, int(t.frames.size()) - 1);
  for (std::size_t i = 0; i + 1 < subs.size(); ++i) {
    const int gap = t.events[i + 1].frame - t.events[i].frame;
    EXPECT_EQ(subs[i].last - subs[i + 1].first + 1, std::min(8, gap / 4) + 1);  // M frames of overlap, + the midpoint
    EXPECT_LT(subs[i + 1].first, subs[i].last);
  }
  Track bad = t;
  bad.events.push_back({999, {}, {0, -1}});
  EXPECT_THROW(cut_subsequences(bad), ValueError);
}

TEST(RigidDiff, AnglesWrapAndSymmetryFolds) {
  EXPECT_NEAR(angle_difference(3.1, -3.1), 6.2 - 2 * 3.14159265358979, 1e-9);
  EXPECT_NEAR(angle_difference(3.14159265358979 / 2, 0, 4), 0, 1e-9);  // a square turned by 90 degrees looks the same
  EXPECT_NEAR(std::abs(angle_difference(0.3, 0, 4)), 0.3, 1e-9);
}

TEST(RigidDiff, AnAugmentedCopyMatchesExactly) {
  // The source, rotated by 0.4 rad and flipped, against the same track
  // transformed that way: Diff 0 for that augmentation, > 0 without it.
  const Track s = source_track();
  const Augmentation aug{0.4, 1.0, true};
  Track t = s;
  for (TrackFrame& f : t.frames) f = augmented(f, aug);
  RigidOptions o;
  o.symmetry = 4;
  const auto ss = cut_subsequences(s), ts = cut_subsequences(t);
  EXPECT_NEAR(sub_sequence_diff(s, ss[1], aug, t, ts[1], o, 0.01), 0, 1e-12);
  EXPECT_GT(sub_sequence_diff(s, ss[1], Augmentation{}, t, ts[1], o, 0.01), 0.1);
}

TEST(RigidFrame, ResidualRoundTrip) {
  const Fitted& f = ball();
  double worst = 0;
  for (int frame : {0, 10, 20, 21, 22, 30, 40}) {
    const TrackFrame& tf = f.exemplar.track.frames[std::size_t(frame)];
    const Image back = apply_map(f.residuals[std::size_t(frame)].view(), f.exemplar.maps[std::size_t(frame)],
                                 {tf.centre, tf.radius});
    worst = std::max(worst, chamfer_distance(alpha_of(back).view(), alpha_of(f.drawings[std::size_t(frame)]).view()));
  }
  std::printf("round trip: worst chamfer %.3f px\n", worst);
  EXPECT_LE(worst, 0.5);
}

TEST(RigidFrame, SelfReproduction) {
  const Fitted& f = ball();
  RigidOptions o;
  o.k = 1;
  o.augment = false;
  const std::vector<RigidFrame> frames = synthesize_deformations({f.exemplar}, f.exemplar.track, o);
  double worst_chamfer = 0, worst_iou = 1;
  for (int i = 0; i < int(frames.size()); ++i) {
    const Image out = render_rigid_frame({f.exemplar}, residuals_of(f), f.exemplar.track, i, frames[std::size_t(i)], W, H);
    const Image a = alpha_of(out), b = alpha_of(f.drawings[std::size_t(i)]);
    worst_chamfer = std::max(worst_chamfer, chamfer_distance(a.view(), b.view()));
    const double overlap = iou(solid(a).view(), solid(b).view());
    if (overlap < 0.97) std::printf("frame %d: IoU %.4f\n", i, overlap);
    worst_iou = std::min(worst_iou, overlap);
  }
  std::printf("self-reproduction: worst chamfer %.3f px, worst IoU %.4f\n", worst_chamfer, worst_iou);
  EXPECT_LE(worst_chamfer, 1.0);
  EXPECT_GE(worst_iou, 0.97);
}

namespace {

// The oracle target: a faster, higher ball thrown to the left (the flip is
// needed), bouncing more often.
Track target_track() { return bouncing_ball({290, 30}, {-3.5, 1}, 16, 1.0, 185, 0.7, -0.08, 64); }

struct Oracle {
  Track target = target_track();
  std::vector<RigidFrame> frames;
  Oracle() { frames = synthesize_deformations({ball().exemplar}, target, RigidOptions{}); }
};

const Oracle& oracle() {
  static const Oracle o;
  return o;
}

}  // namespace

TEST(RigidOracle, StretchFollowsTheGenerator) {
  const Oracle& o = oracle();
  ASSERT_GE(o.target.events.size(), 3u);
  std::vector<double> got, want;
  for (int f = 0; f < int(o.frames.size()); ++f) {
    const Vec2 v = o.target.frames[std::size_t(f)].velocity;
    got.push_back(stretch_along(o.frames[std::size_t(f)].D, v));
    want.push_back(stretch_along(generator_map(o.target, f, ExemplarStyle{}), v));
  }
  const double r = correlation(got, want);
  std::printf("oracle: stretch correlation %.3f\n", r);
  EXPECT_GE(r, 0.9);
}

TEST(RigidOracle, SquashPeaksAtEventsAndFarFramesStayRigid) {
  const Oracle& o = oracle();
  for (const RigidEvent& e : o.target.events) {
    int best = -1;
    double least = 1e9;
    for (int f = std::max(0, e.frame - 4); f <= std::min(int(o.frames.size()) - 1, e.frame + 4); ++f) {
      const double s = stretch_along(o.frames[std::size_t(f)].D, e.normal);
      if (s < least) least = s, best = f;
    }
    EXPECT_LE(std::abs(best - e.frame), 1) << "event at " << e.frame;
    EXPECT_LT(least, 0.9) << "no squash at event " << e.frame;
  }
  // Far from events the output is no more deformed than the exemplar's own
  // rigid frames are (the pencil's wobble and overshoot, ~1 px: the fit sees
  // them), and within 0.06 radii of the circle.
  double worst = 0, exemplar = 0;
  for (int f = 0; f < int(o.frames.size()); ++f)
    if (distance_to_event(o.target, f) > 6) worst = std::max(worst, outline_deviation(o.frames[std::size_t(f)].D));
  const Fitted& b = ball();
  for (int f = 0; f < int(b.exemplar.maps.size()); ++f)
    if (distance_to_event(b.exemplar.track, f) > 6) exemplar = std::max(exemplar, outline_deviation(b.exemplar.maps[std::size_t(f)]));
  std::printf("oracle: far from events the outline deviates <= %.4f radii (the exemplar's rigid frames: %.4f)\n", worst,
              exemplar);
  EXPECT_LE(worst, exemplar);
  EXPECT_LE(worst, 0.06);
}

TEST(RigidOracle, ContactsCloseAtEvents) {
  const Oracle& o = oracle();
  const Fitted& f = ball();
  const std::vector<Vec2> shifts = contact_shifts({f.exemplar}, residuals_of(f), o.target, o.frames, W, H, 3);
  for (const RigidEvent& e : o.target.events) {
    const Image out = render_rigid_frame({f.exemplar}, residuals_of(f), o.target, e.frame, o.frames[std::size_t(e.frame)],
                                         W, H, shifts[std::size_t(e.frame)]);
    const Image unfixed = render_rigid_frame({f.exemplar}, residuals_of(f), o.target, e.frame, o.frames[std::size_t(e.frame)], W, H);
    std::printf("contact at %d: gap %.3f px (unfixed %.3f px)\n", e.frame, contact_gap(out.view(), e), contact_gap(unfixed.view(), e));
    EXPECT_LE(std::abs(contact_gap(out.view(), e)), 1.0);
  }
}

// (worst D_hat jump at the sub-sequence overlaps, median frame-to-frame jump).
static std::pair<double, double> overlap_and_median_jumps(const Track& target, const std::vector<RigidFrame>& frames) {
  std::vector<double> jumps;
  for (std::size_t f = 1; f < frames.size(); ++f) {
    QuadraticMap d;
    for (std::size_t i = 0; i < 12; ++i) d.d[i] = frames[f].D.d[i] - frames[f - 1].D.d[i] + QuadraticMap::identity().d[i];
    jumps.push_back(distance_from_identity(d));
  }
  std::vector<double> sorted = jumps;
  std::sort(sorted.begin(), sorted.end());
  const auto subs = cut_subsequences(target);
  double worst = 0;
  for (std::size_t i = 0; i + 1 < subs.size(); ++i)
    for (int f = subs[i + 1].first; f <= subs[i].last + 1; ++f) worst = std::max(worst, jumps[std::size_t(f - 1)]);
  return {worst, sorted[sorted.size() / 2]};
}

TEST(RigidOracle, OverlapsStitchSmoothly) {
  const Oracle& o = oracle();
  const auto [worst, median] = overlap_and_median_jumps(o.target, o.frames);
  std::printf("stitching: worst overlap jump %.4f, median jump %.4f\n", worst, median);
  EXPECT_LE(worst, 1.5 * median);
}

// Overlaps that disagree: two exemplars of different styles (a stretchy
// fast ball, a slow one that only squashes, over a wide ramp) matched to
// neighbouring events of a target (bounces at 10, 26, 38, 49: the first
// sub-sequence takes the squash-only exemplar, the others the stretchy one). Without
// the overlap blend the hard cut at the overlap jumps; with it, it does not.
TEST(RigidMethod, OverlapBlendHidesDisagreeingSubSequences) {
  auto generated = [](const Track& track, const ExemplarStyle& style) {
    RigidExemplar e{track, {}};
    for (int f = 0; f < int(track.frames.size()); ++f) e.maps.push_back(generator_map(track, f, style));
    return e;
  };
  ExemplarStyle stretchy, squashy;
  stretchy.stretch = 1.5, stretchy.squash = 0.5, stretchy.bend = 0.5;
  squashy.stretch = 0, squashy.squash = 0.6, squashy.bend = 0, squashy.squash_frames = 6;
  const std::vector<RigidExemplar> exemplars{
      generated(bouncing_ball({40, 50}, {4.5, 0}, 18, 1.2, 180, 0.6, 0.05, 48), stretchy),
      generated(bouncing_ball({40, 120}, {1.5, 0}, 18, 0.5, 180, 0.6, 0.05, 48), squashy)};
  const Track target = bouncing_ball({290, 120}, {-3.0, 0}, 16, 1.0, 185, 0.8, -0.05, 56);
  RigidOptions options;
  options.k = 1, options.scales = 1;
  const auto blended = overlap_and_median_jumps(target, synthesize_deformations(exemplars, target, options));
  options.overlap_blend = false;
  const auto cut = overlap_and_median_jumps(target, synthesize_deformations(exemplars, target, options));
  std::printf("disagreeing overlaps: worst jump %.4f against median %.4f blended (%.2fx), %.4f against %.4f cut (%.2fx)\n",
              blended.first, blended.second, blended.first / blended.second, cut.first, cut.second,
              cut.first / cut.second);
  EXPECT_GT(cut.first, 1.5 * cut.second);
  EXPECT_LE(blended.first, 1.5 * blended.second);
}

TEST(RigidMethod, BadInputIsNamed) {
  RigidExemplar empty;
  EXPECT_THROW(synthesize_deformations({}, source_track(), RigidOptions{}), ValueError);
  empty.track = source_track();
  EXPECT_THROW(synthesize_deformations({empty}, source_track(), RigidOptions{}), ValueError);
}

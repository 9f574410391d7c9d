#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "tempera/error.hpp"
#include "tempera/gaussian_blur.hpp"
#include "tempera/lazyfluids.hpp"

using namespace tempera;

namespace {

// Smoke-like RGBA exemplar: smoothed noise in RGB, a soft alpha disc.
Image smoke_exemplar(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Image noise(n, n, 3);
  for (std::size_t i = 0; i < noise.pixel_count() * 3; ++i) noise.data()[i] = u(rng);
  const Image smooth = gaussian_blur(noise.view(), 0.7f);
  Image out(n, n, 4);
  const float c = 0.5f * float(n - 1), r = 0.42f * float(n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      for (int ch = 0; ch < 3; ++ch) out.at(x, y, ch) = 0.5f + 2.0f * (smooth.at(x, y, ch) - 0.5f);
      out.at(x, y, 3) = std::clamp((r - std::hypot(x - c, y - c)) / 1.5f, 0.0f, 1.0f);
    }
  return out;
}

Image disc(int w, int h, float cx, float cy, float r) {
  Image a(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) a.at(x, y, 0) = std::clamp(r - std::hypot(x - cx, y - cy) + 0.5f, 0.0f, 1.0f);
  return a;
}

Image constant_flow(int w, int h, float vx, float vy) {
  Image f(w, h, 2);
  for (std::size_t i = 0; i < f.pixel_count(); ++i) f.data()[2 * i] = vx, f.data()[2 * i + 1] = vy;
  return f;
}

// Rotation about (cx, cy) by `omega` radians per frame: p moves to R p.
Image rotational_flow(int w, int h, float cx, float cy, float omega) {
  Image f(w, h, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float dx = x - cx, dy = y - cy;
      f.at(x, y, 0) = std::cos(omega) * dx - std::sin(omega) * dy - dx;
      f.at(x, y, 1) = std::sin(omega) * dx + std::cos(omega) * dy - dy;
    }
  return f;
}

LazyFluidsOptions test_options(PatchUsage usage = PatchUsage::Uniform, int threads = 2) {
  LazyFluidsOptions o = default_lazyfluids_options();
  o.synthesis.usage = usage;
  o.synthesis.em_iterations = 3;
  o.synthesis.threads = threads;
  return o;
}

// Uses of each exemplar patch centre by the target's synthesized pixels.
std::map<int, int> usage_counts(const FluidFrameResult& r, int exemplar_width) {
  std::map<int, int> uses;
  for (int y = 0; y < r.target_labels.height(); ++y)
    for (int x = 0; x < r.target_labels.width(); ++x) {
      if (r.target_labels.at(x, y, 0) < 0) continue;
      const ExemplarMatch m = r.synthesis.match(x, y);
      ++uses[int(std::lround(m.y)) * exemplar_width + int(std::lround(m.x))];
    }
  return uses;
}

struct UsageCheck {
  int K = 0;
  bool counts_ok = true;  // every valid source of the segment used K or K+1 times
  bool remainder_ok = true;  // exactly R of them K+1 times
};

// Per segment label (0 boundary, 1 interior) of a one-frame run.
std::vector<UsageCheck> check_usage(const Image& exemplar, const FluidFrameResult& r, int margin) {
  const AlphaSegments src = alpha_segments(extract_channels(exemplar.view(), 3, 1).view(), AlphaSegmentOptions{});
  const auto uses = usage_counts(r, exemplar.width());
  std::vector<UsageCheck> out;
  for (int label = 0; label < 2; ++label) {
    int z = 0, targets = 0, at_k1 = 0;
    for (int y = margin; y < exemplar.height() - margin; ++y)
      for (int x = margin; x < exemplar.width() - margin; ++x) z += src.labels.at(x, y, 0) == float(label);
    for (std::size_t i = 0; i < r.target_labels.pixel_count(); ++i) targets += r.target_labels.data()[i] == float(label);
    UsageCheck c;
    c.K = targets / z;
    for (int y = margin; y < exemplar.height() - margin; ++y)
      for (int x = margin; x < exemplar.width() - margin; ++x) {
        if (src.labels.at(x, y, 0) != float(label)) continue;
        const auto it = uses.find(y * exemplar.width() + x);
        const int n = it == uses.end() ? 0 : it->second;
        c.counts_ok &= n == c.K || n == c.K + 1;
        at_k1 += n == c.K + 1;
      }
    c.remainder_ok = at_k1 == targets % z;
    out.push_back(c);
  }
  return out;
}

FluidFrameResult first_frame(const Image& exemplar, const Image& alpha, const LazyFluidsOptions& o) {
  FluidFrameInput in;
  in.style = in.previous_style = exemplar.view();
  in.target_alpha = alpha.view();
  return stylize_fluid_frame(in, o);
}

// Mean over the interior of the 5x5 local standard deviation of RGB.
double interior_contrast(const Image& image, const Image& labels) {
  double sum = 0;
  int n = 0;
  for (int y = 2; y < image.height() - 2; ++y)
    for (int x = 2; x < image.width() - 2; ++x) {
      if (labels.at(x, y, 0) != interior_label) continue;
      for (int c = 0; c < 3; ++c) {
        double s = 0, s2 = 0;
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) s += image.at(x + dx, y + dy, c), s2 += std::pow(image.at(x + dx, y + dy, c), 2);
        sum += std::sqrt(std::max(0.0, s2 / 25 - (s / 25) * (s / 25)));
        ++n;
      }
    }
  return n ? sum / n : 0;
}

// Mean |X^t - X̂^{t-1}| (RGBA) where λ_q > 0, over frames 1..n-1.
double warp_error(const std::vector<Image>& frames, const std::vector<Image>& alphas, const Image& flow) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t t = 1; t < frames.size(); ++t) {
    const Image advected = advect_output(frames[t - 1].view(), flow.view());
    const Image w = temporal_weights(alphas[t].view(), advected.view(), 1.0f);
    for (std::size_t i = 0; i < w.pixel_count(); ++i) {
      if (!(w.data()[i] > 0) || alphas[t].data()[i] < 0.5f) continue;
      for (int c = 0; c < 4; ++c, ++n) sum += std::abs(frames[t].data()[i * 4 + c] - advected.data()[i * 4 + c]);
    }
  }
  return sum / double(std::max<std::size_t>(1, n));
}

// Horizontal shift of `b` against `a` (RGB, where both are opaque) at the
// peak of their normalised cross-correlation, refined by a parabola.
double horizontal_shift(const Image& a, const Image& b) {
  std::vector<double> score;
  const int max_shift = 5;
  for (int s = -max_shift; s <= max_shift; ++s) {
    double ab = 0, aa = 0, bb = 0;
    for (int y = 0; y < a.height(); ++y)
      for (int x = std::max(0, -s); x < std::min(a.width(), a.width() - s); ++x) {
        if (a.at(x, y, 3) < 0.99f || b.at(x + s, y, 3) < 0.99f) continue;
        for (int c = 0; c < 3; ++c) {
          const double u = a.at(x, y, c) - 0.5, v = b.at(x + s, y, c) - 0.5;
          ab += u * v, aa += u * u, bb += v * v;
        }
      }
    score.push_back(ab / std::sqrt(aa * bb + 1e-12));
  }
  const int k = int(std::max_element(score.begin(), score.end()) - score.begin());
  double offset = 0;
  if (k > 0 && k + 1 < int(score.size())) {
    const double l = score[k - 1], m = score[k], r = score[k + 1];
    offset = 0.5 * (l - r) / (l - 2 * m + r);
  }
  return k - max_shift + offset;
}

}  // namespace

TEST(LazyFluids, TemporalWeightIsEquation56Exactly) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Image target(7, 5, 1), advected(7, 5, 4);
  for (std::size_t i = 0; i < target.pixel_count(); ++i) target.data()[i] = u(rng);
  for (std::size_t i = 0; i < advected.pixel_count() * 4; ++i) advected.data()[i] = u(rng);
  const Image w = temporal_weights(target.view(), advected.view(), 0.2f);
  for (std::size_t i = 0; i < w.pixel_count(); ++i)
    EXPECT_EQ(w.data()[i], (1.0f - std::max(0.0f, target.data()[i] - advected.data()[i * 4 + 3])) * 0.2f);
}

TEST(LazyFluids, AdvectionCarriesTheOutputAndIsTransparentFromOutside) {
  Image prev(8, 4, 4, 0.0f);
  for (int y = 0; y < 4; ++y) prev.at(2, y, 3) = 1, prev.at(2, y, 0) = 0.5f;
  const Image out = advect_output(prev.view(), constant_flow(8, 4, 3, 0).view());
  EXPECT_FLOAT_EQ(out.at(5, 1, 3), 1.0f);
  EXPECT_FLOAT_EQ(out.at(5, 1, 0), 0.5f);
  EXPECT_FLOAT_EQ(out.at(2, 1, 3), 0.0f);
  EXPECT_FLOAT_EQ(out.at(0, 1, 3), 0.0f);  // came from x = -3: outside
  const Image ones = advect_output(Image(8, 4, 4, 1.0f).view(), constant_flow(8, 4, 3, 0).view());
  EXPECT_EQ(ones.at(1, 0, 3), 0.0f);  // a clamped warp would give 1 here
  EXPECT_EQ(ones.at(4, 0, 3), 1.0f);
}

TEST(LazyFluids, RotationsTurnClockwise) {
  Image a(3, 2, 1);
  for (int i = 0; i < 6; ++i) a.data()[i] = float(i);  // rows 0 1 2 / 3 4 5
  const Image r = rotate_quarter_turns(a.view(), 1);
  ASSERT_EQ(r.width(), 2);
  ASSERT_EQ(r.height(), 3);
  EXPECT_EQ(r.at(0, 0, 0), 3.0f);  // the bottom-left corner goes to the top-left
  EXPECT_EQ(r.at(1, 0, 0), 0.0f);
  const Image back = rotate_quarter_turns(rotate_quarter_turns(r.view(), 2).view(), 1);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(back.data()[i], a.data()[i]);
}

TEST(LazyFluids, MotionBlurStreaksAlongTheFlowOnly) {
  Image dot(15, 15, 1);
  dot.at(7, 7, 0) = 1;
  const Image out = motion_blur_along_flow(dot.view(), constant_flow(15, 15, 2, 0).view(), 6);
  EXPECT_GT(out.at(9, 7, 0), 0.1f);  // along x
  EXPECT_EQ(out.at(7, 9, 0), 0.0f);  // not across
  EXPECT_LT(out.at(7, 7, 0), 0.5f);
}

TEST(LazyFluids, UniformUsageIsKOrKPlusOnePerSegment) {
  const Image exemplar = smoke_exemplar(20, 1);
  // Valid centres per segment about 60-100: these targets give K about 4, 30, 100.
  for (const int size : {40, 100, 180}) {
    const Image alpha = disc(size, size, 0.5f * (size - 1), 0.5f * (size - 1), 0.42f * size);
    const FluidFrameResult r = first_frame(exemplar, alpha, test_options());
    const auto checks = check_usage(exemplar, r, 2);
    for (int label = 0; label < 2; ++label) {
      SCOPED_TRACE(testing::Message() << "target " << size << " segment " << label << " K " << checks[label].K);
      EXPECT_GE(checks[label].K, 3);
      EXPECT_TRUE(checks[label].counts_ok);
      EXPECT_TRUE(checks[label].remainder_ok);
    }
    if (size == 180) {
      EXPECT_GE(checks[1].K, 80);
      ASSERT_GE(r.synthesis.levels.back().usage_rounds, checks[1].K);  // every use by reversed retrieval
      EXPECT_EQ(r.synthesis.levels.back().reversed_coverage, 1.0);
    }
  }
  const Image alpha = disc(100, 100, 49.5f, 49.5f, 42);
  const auto none = check_usage(exemplar, first_frame(exemplar, alpha, test_options(PatchUsage::None)), 2);
  EXPECT_FALSE(none[1].counts_ok);
}

TEST(LazyFluids, AlphaFollowsTheTargetAndSegmentsNeverMix) {
  const Image exemplar = smoke_exemplar(24, 2);
  const Image alpha = disc(60, 50, 30, 25, 18);
  const FluidFrameResult r = first_frame(exemplar, alpha, test_options());
  int inter = 0, uni = 0;
  for (std::size_t i = 0; i < alpha.pixel_count(); ++i) {
    const bool a = r.image.data()[i * 4 + 3] > 0.5f, b = alpha.data()[i] > 0.5f;
    inter += a && b, uni += a || b;
  }
  EXPECT_GE(double(inter) / uni, 0.9);
  const AlphaSegments src = alpha_segments(extract_channels(exemplar.view(), 3, 1).view(), AlphaSegmentOptions{});
  for (int y = 0; y < 50; ++y)
    for (int x = 0; x < 60; ++x) {
      if (r.target_labels.at(x, y, 0) < 0) {
        EXPECT_EQ(r.image.at(x, y, 3), 0.0f);
        continue;
      }
      const ExemplarMatch m = r.synthesis.match(x, y);
      EXPECT_EQ(src.labels.at(int(std::lround(m.x)), int(std::lround(m.y)), 0), r.target_labels.at(x, y, 0))
          << x << "," << y;
    }
}

TEST(LazyFluids, SameSeedSameFramesForAnyThreadCount) {
  const Image exemplar = smoke_exemplar(20, 3);
  std::vector<Image> alphas = {disc(40, 30, 18, 15, 11), disc(40, 30, 20, 15, 11), disc(40, 30, 22, 15, 11)};
  const Image flow = constant_flow(40, 30, 2, 0);
  std::vector<ImageView> a, f;
  for (const Image& i : alphas) a.push_back(i.view()), f.push_back(flow.view());
  LazyFluidsOptions o = test_options(PatchUsage::Uniform, 1);
  o.rotations = true;
  o.motion_blur = 3;
  const auto one = stylize_fluid_sequence({exemplar.view()}, a, f, o);
  o.synthesis.threads = 2;
  const auto two = stylize_fluid_sequence({exemplar.view()}, a, f, o);
  ASSERT_EQ(one.size(), 3u);
  for (std::size_t t = 0; t < 3; ++t)
    for (std::size_t i = 0; i < one[t].pixel_count() * 4; ++i) ASSERT_EQ(one[t].data()[i], two[t].data()[i]) << t;
}

TEST(LazyFluids, TemporalTermHalvesTheWarpErrorAndTransportsAtTheFlowSpeed) {
  const Image exemplar = smoke_exemplar(24, 4);
  const int w = 72, h = 40, n = 6;
  const Image flow = constant_flow(w, h, 2, 0);
  std::vector<Image> alphas;
  std::vector<ImageView> a, f;
  for (int t = 0; t < n; ++t) alphas.push_back(disc(w, h, 22.0f + 2 * t, 19.5f, 15));
  for (const Image& i : alphas) a.push_back(i.view()), f.push_back(flow.view());
  LazyFluidsOptions o = test_options();
  const auto coherent = stylize_fluid_sequence({exemplar.view()}, a, f, o);
  o.temporal_weight = 0;
  const auto independent = stylize_fluid_sequence({exemplar.view()}, a, f, o);
  const double e_coherent = warp_error(coherent, alphas, flow), e_independent = warp_error(independent, alphas, flow);
  RecordProperty("warp_error_lambda_0.2", std::to_string(e_coherent));
  RecordProperty("warp_error_lambda_0", std::to_string(e_independent));
  EXPECT_LE(e_coherent, 0.5 * e_independent) << e_coherent << " vs " << e_independent;
  for (int t = 1; t < n; ++t) EXPECT_NEAR(horizontal_shift(coherent[t - 1], coherent[t]), 2.0, 0.5) << "frame " << t;
}

TEST(LazyFluids, RejectsBadInputWithClearErrors) {
  const Image exemplar = smoke_exemplar(20, 5);
  FluidFrameInput in;
  in.style = in.previous_style = exemplar.view();
  const Image rgb(20, 20, 3), alpha = disc(30, 30, 15, 15, 9);
  in.target_alpha = rgb.view();
  EXPECT_THROW(stylize_fluid_frame(in, test_options()), ValueError);
  in.target_alpha = alpha.view();
  LazyFluidsOptions o = test_options();
  o.alpha_lower = 0.95f;
  EXPECT_THROW(stylize_fluid_frame(in, o), ValueError);
  EXPECT_THROW(stylize_fluid_sequence({exemplar.view()}, {alpha.view()}, {}, test_options()), ValueError);
}

namespace {

// Interior contrast of frame 10 and of the last frame of a rotating disc.
std::pair<double, double> washout_contrast(PatchUsage usage, int frames) {
  const Image exemplar = smoke_exemplar(24, 6);
  const int n = 48;
  const Image alpha = disc(n, n, 23.5f, 23.5f, 20), flow = rotational_flow(n, n, 23.5f, 23.5f, 0.08f);
  std::vector<ImageView> a(std::size_t(frames), alpha.view()), f(std::size_t(frames), flow.view());
  LazyFluidsOptions o = test_options(usage);
  o.temporal_weight = 1;  // strong pull to the advected frame: what washes out without uniform usage
  const auto out = stylize_fluid_sequence({exemplar.view()}, a, f, o);
  const Image labels = alpha_segments(alpha.view(), AlphaSegmentOptions{}).labels;
  return {interior_contrast(out[9], labels), interior_contrast(out.back(), labels)};
}

}  // namespace

// Wash-out (L2), the short calibrated version of the 120-frame run in
// bench/bench_lazyfluids.py: 30 frames of rotation.
TEST(LazyFluids, UniformUsageKeepsTheContrastWhereNoUsageWashesOut) {
  const auto [c10, c_last] = washout_contrast(PatchUsage::Uniform, 30);
  const auto [n10, n_last] = washout_contrast(PatchUsage::None, 30);
  RecordProperty("uniform_ratio", std::to_string(c_last / c10));
  RecordProperty("none_ratio", std::to_string(n_last / n10));
  EXPECT_GE(c_last / c10, 0.9) << c10 << " -> " << c_last;
  EXPECT_LT(n_last / n10, 0.7) << n10 << " -> " << n_last;
}

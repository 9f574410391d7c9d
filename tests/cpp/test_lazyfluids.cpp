#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <map>
#include <random>

#include "tempera/engine/error.hpp"
#include "tempera/engine/gaussian_blur.hpp"
#include "tempera/methods/lazyfluids/lazyfluids.hpp"

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

using Complex = std::complex<double>;

// In-place DFT of every row (along_rows) or column of a w x h grid; inverse
// with sign +1 (unnormalised).
void dft_lines(std::vector<Complex>& g, int w, int h, bool along_rows, double sign) {
  const int n = along_rows ? w : h, lines = along_rows ? h : w;
  std::vector<Complex> line(std::size_t(n), 0), out(std::size_t(n), 0);
  for (int l = 0; l < lines; ++l) {
    auto at = [&](int k) -> Complex& { return along_rows ? g[std::size_t(l * w + k)] : g[std::size_t(k * w + l)]; };
    for (int k = 0; k < n; ++k) line[std::size_t(k)] = at(k);
    for (int k = 0; k < n; ++k) {
      Complex sum = 0;
      for (int j = 0; j < n; ++j) sum += line[std::size_t(j)] * std::polar(1.0, sign * 2 * M_PI * k * j / n);
      out[std::size_t(k)] = sum;
    }
    for (int k = 0; k < n; ++k) at(k) = out[std::size_t(k)];
  }
}

void dft2(std::vector<Complex>& g, int w, int h, double sign) {
  dft_lines(g, w, h, true, sign);
  dft_lines(g, w, h, false, sign);
}

// Motion of `b`'s texture against `a`'s by phase correlation: the luminance
// in the window where both are opaque (a window that does not move, so only
// the texture's motion shows), the normalised cross-power spectrum
// transformed back, its peak refined by a parabola along x.
std::pair<double, double> phase_correlation_shift(const Image& a, const Image& b) {
  const int w = a.width(), h = a.height();
  std::vector<Complex> fa(std::size_t(w * h), 0), fb(std::size_t(w * h), 0);
  auto lum = [](const Image& i, int x, int y) { return (i.at(x, y, 0) + i.at(x, y, 1) + i.at(x, y, 2)) / 3.0; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (a.at(x, y, 3) > 0.99f && b.at(x, y, 3) > 0.99f)
        fa[std::size_t(y * w + x)] = lum(a, x, y) - 0.5, fb[std::size_t(y * w + x)] = lum(b, x, y) - 0.5;
  dft2(fa, w, h, -1), dft2(fb, w, h, -1);
  for (std::size_t i = 0; i < fa.size(); ++i) {
    const Complex c = fb[i] * std::conj(fa[i]);
    fa[i] = std::abs(c) > 1e-12 ? c / std::abs(c) : 0;
  }
  dft2(fa, w, h, +1);
  std::size_t best = 0;
  for (std::size_t i = 0; i < fa.size(); ++i)
    if (fa[i].real() > fa[best].real()) best = i;
  const int px = int(best) % w, py = int(best) / w;
  auto r = [&](int x) { return fa[std::size_t(py * w + (x + w) % w)].real(); };
  const double l = r(px - 1), m = r(px), rr = r(px + 1);
  const double sub = (l - 2 * m + rr) != 0 ? 0.5 * (l - rr) / (l - 2 * m + rr) : 0;
  return {(px > w / 2 ? px - w : px) + sub, py > h / 2 ? py - h : py};
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
  const Image exemplar = smoke_exemplar(32, 1);
  // These targets give the interior K about 4, 30 and 100 (the boundary less).
  for (const int size : {52, 126, 222}) {
    const Image alpha = disc(size, size, 0.5f * (size - 1), 0.5f * (size - 1), 0.42f * size);
    const FluidFrameResult r = first_frame(exemplar, alpha, test_options());
    const auto checks = check_usage(exemplar, r, 2);
    for (int label = 0; label < 2; ++label) {
      SCOPED_TRACE(testing::Message() << "target " << size << " segment " << label << " K " << checks[label].K);
      RecordProperty(concat("K_", size, "_segment_", label), checks[label].K);
      EXPECT_GE(checks[label].K, 2);
      EXPECT_TRUE(checks[label].counts_ok);
      EXPECT_TRUE(checks[label].remainder_ok);
    }
    if (size == 222) {
      EXPECT_GE(checks[1].K, 80);
      RecordProperty("rounds_222", r.synthesis.levels.back().usage_rounds);
      ASSERT_GE(r.synthesis.levels.back().usage_rounds, checks[1].K);  // every use by reversed retrieval
      EXPECT_EQ(r.synthesis.levels.back().reversed_coverage, 1.0);
    }
  }
  const Image alpha = disc(126, 126, 62.5f, 62.5f, 53);
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
  // Transport: a still mask with the flow inside it, so that only the
  // temporal term can move the texture (a moving mask would carry even
  // independent frames along, the guides being translation-invariant).
  const Image still = disc(w, h, 35.5f, 19.5f, 17);
  const std::vector<ImageView> s(std::size_t(n), still.view());
  const auto moving = stylize_fluid_sequence({exemplar.view()}, s, f, test_options());
  const auto frozen = stylize_fluid_sequence({exemplar.view()}, s, f, o);
  int carried = 0;
  for (int t = 1; t < n; ++t) {
    const auto [dx, dy] = phase_correlation_shift(moving[t - 1], moving[t]);
    RecordProperty(concat("shift_", t), std::to_string(dx));
    EXPECT_NEAR(dx, 2.0, 0.5) << "frame " << t;
    EXPECT_NEAR(dy, 0.0, 0.5) << "frame " << t;
    carried += std::abs(phase_correlation_shift(frozen[t - 1], frozen[t]).first - 2) < 0.5;
  }
  EXPECT_EQ(carried, 0);  // λ = 0: nothing carries the texture
}

// The warm start solves only the finest level from the advected field: the
// texture must still be carried at the flow speed, every segment's usage
// stay K or K+1, and the warp error stay near the cold start's.
TEST(LazyFluids, WarmStartKeepsTransportUsageAndCoherence) {
  const Image exemplar = smoke_exemplar(24, 4);
  const int w = 72, h = 40, n = 6;
  const Image flow = constant_flow(w, h, 2, 0), still = disc(w, h, 35.5f, 19.5f, 17);
  const std::vector<ImageView> s(std::size_t(n), still.view()), f(std::size_t(n), flow.view());
  const std::vector<Image> alphas(std::size_t(n), still);
  LazyFluidsOptions o = test_options();
  o.warm_start = false;
  const auto cold = stylize_fluid_sequence({exemplar.view()}, s, f, o);
  o.warm_start = true;
  const auto warm = stylize_fluid_sequence({exemplar.view()}, s, f, o);
  for (int t = 1; t < n; ++t) EXPECT_NEAR(phase_correlation_shift(warm[t - 1], warm[t]).first, 2.0, 0.5) << t;
  const double e_cold = warp_error(cold, alphas, flow), e_warm = warp_error(warm, alphas, flow);
  RecordProperty("warp_error_cold", std::to_string(e_cold));
  RecordProperty("warp_error_warm", std::to_string(e_warm));
  EXPECT_LE(e_warm, 1.25 * e_cold);
  // One warm frame by itself: the usage rule still holds.
  OffsetField previous;
  FluidFrameInput in;
  in.style = in.previous_style = exemplar.view();
  in.target_alpha = still.view();
  previous = stylize_fluid_frame(in, o).synthesis.field;
  const Image advected = advect_output(cold[0].view(), flow.view());
  in.advected = advected.view();
  in.previous_field = &previous;
  in.flow_previous = flow.view();
  const FluidFrameResult r = stylize_fluid_frame(in, o);
  ASSERT_EQ(r.synthesis.levels.size(), 1u);  // the finest level only
  for (const UsageCheck& c : check_usage(exemplar, r, 2)) EXPECT_TRUE(c.counts_ok && c.remainder_ok);
}

// Where the advected previous output holds no material nothing carried a
// match: those pixels start afresh. A frame whose material is all new (the
// previous output transparent) is then the same whatever the previous field
// held; carried matches would make the two differ.
TEST(LazyFluids, WarmStartRestartsWhereNothingWasCarried) {
  const Image exemplar = smoke_exemplar(24, 4);
  const Image flow = constant_flow(72, 40, 2, 0), alpha = disc(72, 40, 35.5f, 19.5f, 17);
  const Image empty(72, 40, 4, 0.0f);
  LazyFluidsOptions o = test_options();
  FluidFrameInput in;
  in.style = in.previous_style = exemplar.view();
  in.target_alpha = alpha.view();
  const OffsetField one = stylize_fluid_frame(in, o).synthesis.field;
  o.synthesis.seed += 1;
  const OffsetField two = stylize_fluid_frame(in, o).synthesis.field;
  o.synthesis.seed -= 1;
  ASSERT_NE(one.x, two.x);
  in.advected = empty.view();
  in.flow_previous = flow.view();
  in.previous_field = &one;
  const FluidFrameResult from_one = stylize_fluid_frame(in, o);
  in.previous_field = &two;
  const FluidFrameResult from_two = stylize_fluid_frame(in, o);
  ASSERT_EQ(from_one.synthesis.levels.size(), 1u);  // warm: the finest level only
  for (std::size_t i = 0; i < from_one.image.pixel_count() * 4; ++i)
    ASSERT_EQ(from_one.image.data()[i], from_two.image.data()[i]) << i;
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

// A smoke exemplar whose texture contrast grows from left (smooth) to right:
// without a usage rule the smooth side wins more and more of the frame.
Image graded_smoke(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Image out = smoke_exemplar(n, seed);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      for (int c = 0; c < 3; ++c)
        out.at(x, y, c) = std::clamp(0.5f + (0.15f + 1.6f * float(x) / float(n - 1)) * (u(rng) - 0.5f), 0.0f, 1.0f);
  return out;
}

// Interior contrast of the first and the last frame of a rotating disc.
std::pair<double, double> washout_contrast(PatchUsage usage, int frames) {
  const int n = 48;
  const Image alpha = disc(n, n, 23.5f, 23.5f, 20), flow = rotational_flow(n, n, 23.5f, 23.5f, 0.08f);
  std::vector<ImageView> a(std::size_t(frames), alpha.view()), f(std::size_t(frames), flow.view());
  LazyFluidsOptions o = test_options(usage);
  o.temporal_weight = 3;  // a strong pull to the advected frame: what washes out without uniform usage
  const Image exemplar = graded_smoke(24, 6);
  const auto out = stylize_fluid_sequence({exemplar.view()}, a, f, o);
  const Image labels = alpha_segments(alpha.view(), AlphaSegmentOptions{}).labels;
  return {interior_contrast(out.front(), labels), interior_contrast(out.back(), labels)};
}

}  // namespace

// Wash-out (L2), the short calibrated version of the 120-frame run in
// bench/bench_lazyfluids.py: 30 frames of rotation, the interior contrast of
// the last frame against the first (without usage control the loss happens
// within the first frames and then levels off, so against frame 10 as the
// issue proposes it would not show; docs/lazyfluids.md).
TEST(LazyFluids, UniformUsageKeepsTheContrastWhereNoUsageWashesOut) {
  const auto [c1, c_last] = washout_contrast(PatchUsage::Uniform, 30);
  const auto [n1, n_last] = washout_contrast(PatchUsage::None, 30);
  RecordProperty("uniform_ratio", std::to_string(c_last / c1));
  RecordProperty("none_ratio", std::to_string(n_last / n1));
  EXPECT_GE(c_last / c1, 0.9) << c1 << " -> " << c_last;
  EXPECT_LT(n_last / n1, 0.75) << n1 << " -> " << n_last;
}

// Bénard et al. 2013 (TCIA): sweeps along rendered motion keep the paint on
// the surfaces. Each test fails when its part is switched off.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tempera/engine/error.hpp"
#include "tempera/engine/solver.hpp"
#include "tempera/methods/stylit/stylit.hpp"
#include "tempera/methods/tcia/tcia.hpp"
#include "tcia_measures.hpp"

using namespace tempera;
using namespace tempera::test;

namespace {

// A surface translating right by `speed` px per frame: its guide is the
// surface's own coordinates (as a texture-coordinate AOV would be).
struct TranslatingShot {
  Image style, style_guide;
  std::vector<Image> guides, v_minus, v_plus, chi_minus, chi_plus;
  Shot shot;

  // `offset`: the exemplar column at the frame's left edge at frame 0.
  TranslatingShot(int frames, int w, int h, float speed, float offset = 20) {
    style = smooth_noise(80, 64, 3, 1);
    style_guide = Image(80, 64, 2);
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 80; ++x) style_guide.at(x, y, 0) = x / 80.0f, style_guide.at(x, y, 1) = y / 64.0f;
    for (int t = 0; t < frames; ++t) {
      Image g(w, h, 2), vm(w, h, 2), vp(w, h, 2), cm(w, h, 1, 1.0f), cp(w, h, 1, 1.0f);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          g.at(x, y, 0) = (x - speed * t + offset) / 80.0f;
          g.at(x, y, 1) = (y + 8) / 64.0f;
          vm.at(x, y, 0) = vp.at(x, y, 0) = speed;
          if (x < speed) cm.at(x, y, 0) = 0;       // enters from the left
          if (x >= w - speed) cp.at(x, y, 0) = 0;  // leaves on the right
        }
      guides.push_back(std::move(g));
      v_minus.push_back(std::move(vm));
      v_plus.push_back(std::move(vp));
      chi_minus.push_back(std::move(cm));
      chi_plus.push_back(std::move(cp));
    }
    shot.style = style.view();
    shot.guide_names = {"uv"};
    shot.style_guides = {style_guide.view()};
    shot.guide_weights = {4.0f};
    for (int t = 0; t < frames; ++t)
      shot.frames.push_back({{guides[t].view()}, v_minus[t].view(), v_plus[t].view(), chi_minus[t].view(),
                             chi_plus[t].view(), {}});
  }

  double mean_flicker(const std::vector<Image>& out) const {
    double sum = 0;
    for (std::size_t t = 1; t < out.size(); ++t)
      sum += flicker(out[t - 1].view(), out[t].view(), v_minus[t].view(), chi_minus[t].view());
    return sum / double(out.size() - 1);
  }
};

// The patch-statistics distance of `out` to the exemplar: the mean, over
// output patches (5 x 5, every 4th pixel), of the squared distance per value
// to the nearest exemplar patch (brute force).
// Over the patches centred in columns [x0, x1) only, every `step`th pixel.
double patch_statistics(const Image& out, const Image& style, int x0 = 0, int x1 = 1 << 20, int step = 4) {
  constexpr int r = 2;
  double sum = 0;
  int count = 0;
  for (int y = r; y < out.height() - r; y += step)
    for (int x = std::max(r, x0); x < std::min(out.width() - r, x1); x += step) {
      double best = 1e30;
      for (int sy = r; sy < style.height() - r; ++sy)
        for (int sx = r; sx < style.width() - r; ++sx) {
          double d = 0;
          for (int dy = -r; dy <= r && d < best; ++dy)
            for (int dx = -r; dx <= r; ++dx)
              for (int c = 0; c < 3; ++c) {
                const double e = out.at(x + dx, y + dy, c) - style.at(sx + dx, sy + dy, c);
                d += e * e;
              }
          best = std::min(best, d);
        }
      sum += best / (3 * (2 * r + 1) * (2 * r + 1));
      ++count;
    }
  return sum / count;
}

}  // namespace

TEST(Tcia, SweepsKeepThePaintOnTheMovingSurface) {
  // Whole-pixel motion: at sub-pixel speeds the flicker figure's bilinear
  // warp of the previous frame has an error floor of its own (measured 0.031
  // at 1.5 px per frame against 0.078 for independent frames).
  const TranslatingShot s(8, 56, 40, 2.0f);
  const TciaOptions coherent = fast_options();
  const std::vector<Image> out = stylize_shot(s.shot, coherent);
  ASSERT_EQ(out.size(), 8u);
  // Per-frame synthesis: the same engine, no temporal term, frames alone.
  TciaOptions alone = fast_options();
  alone.temporal_weight = 0;
  std::vector<Image> independent;
  for (std::size_t t = 0; t < s.shot.frames.size(); ++t) {
    Shot one = s.shot;
    one.frames = {s.shot.frames[t]};
    independent.push_back(stylize_shot(one, alone).front());
  }
  const double f_tcia = s.mean_flicker(out), f_alone = s.mean_flicker(independent);
  RecordProperty("flicker", std::to_string(f_tcia) + " vs " + std::to_string(f_alone));
  EXPECT_LE(f_tcia, 0.3 * f_alone) << f_tcia << " vs " << f_alone;
}

TEST(Tcia, CoherenceKeepsThePatchStatisticsAndDoesNotDrift) {
  // 10 frames: the flicker along the motion is low all through the shot
  // (no drift: the first and last thirds within 1.5x, plus 0.002, 2% of
  // the per-frame flicker, for the noise of such small figures), and every
  // coherent frame is as close to the exemplar's patches as per-frame
  // synthesis is on average (1.2x): coherence does not wash the paint out.
  // The surface stays 4 px inside the exemplar (a patch centre needs 3):
  // its border columns can only be copied off-centre, by any method. With
  // w_tc = 1 the shot's last two frames failed (0.00021 against 0.00011,
  // last-third flicker 0.00085): the default is 3 (tcia.hpp).
  const TranslatingShot s(10, 52, 40, 2.0f, 22.0f);
  const std::vector<Image> out = stylize_shot(s.shot, fast_options());
  TciaOptions alone = fast_options();
  alone.temporal_weight = 0;
  double alone_stats = 0;
  for (std::size_t t = 0; t < s.shot.frames.size(); ++t) {
    Shot one = s.shot;
    one.frames = {s.shot.frames[t]};
    alone_stats += patch_statistics(stylize_shot(one, alone).front(), s.style) / double(s.shot.frames.size());
  }
  std::string stats;
  for (const Image& frame : out) {
    const double d = patch_statistics(frame, s.style);
    stats += std::to_string(d) + " ";
    EXPECT_LE(d, 1.2 * alone_stats) << "per-frame mean " << alone_stats;
  }
  RecordProperty("patch_statistics", stats + "vs per-frame mean " + std::to_string(alone_stats));
  auto third = [&](std::size_t from) {
    double f = 0;
    for (std::size_t t = from; t < from + 3; ++t)
      f += flicker(out[t - 1].view(), out[t].view(), s.v_minus[t].view(), s.chi_minus[t].view());
    return f / 3;
  };
  const double first = third(1), last = third(7);
  RecordProperty("flicker_thirds", std::to_string(first) + " " + std::to_string(last));
  EXPECT_LE(std::max(first, last), 1.5 * std::min(first, last) + 0.002) << first << " vs " << last;
}

// Fig. 4: the surface enters at the left edge, 3 px per frame. Patches
// centred in freshly disoccluded columns (entered within the last 3 frames)
// are as close to the exemplar's as those elsewhere (1.2x, plus 1e-5 for
// figures that are 0). With χ forced to 1 the sweeps carry the neighbour's
// paint from outside the frame into the band, and the same test fails.
TEST(Tcia, DisoccludedBandsAreFreshPaintOnlyWhereChiSaysSo) {
  auto band_and_rest = [](bool chi_forced_to_one) {
    TranslatingShot s(8, 48, 40, 3.0f, 26.0f);
    if (chi_forced_to_one)
      for (auto* chi : {&s.chi_minus, &s.chi_plus})
        for (Image& c : *chi) std::fill(c.data(), c.data() + c.pixel_count(), 1.0f);
    const std::vector<Image> out = stylize_shot(s.shot, fast_options());
    double band = 0, rest = 0;
    for (std::size_t t = 1; t < out.size(); ++t) {
      band += patch_statistics(out[t], s.style, 0, 9, 1) / double(out.size() - 1);
      rest += patch_statistics(out[t], s.style, 12, 1 << 20, 2) / double(out.size() - 1);
    }
    return std::pair{band, rest};
  };
  const auto [band, rest] = band_and_rest(false);
  const auto [forced_band, forced_rest] = band_and_rest(true);
  RecordProperty("band_vs_rest", std::to_string(band) + " " + std::to_string(rest) + "; chi = 1: " +
                                     std::to_string(forced_band) + " " + std::to_string(forced_rest));
  EXPECT_LE(band, 1.2 * rest + 1e-5) << band << " vs " << rest;
  EXPECT_GT(forced_band, 1.2 * forced_rest + 1e-5) << forced_band << " vs " << forced_rest;
}

// Fig. 11: a texture fixed to a surface that moves 2 px per frame is the
// ground truth (another texture than the exemplar's, so only the keys can
// bring it in); its frames 0 and 10 are exact keys. The
// in-betweens beat advecting both keys to the frame and crossfading them
// by time (where a key does not see a pixel, its advected copy is smeared
// from the frame's edge, a ghost in the crossfade), in mean SSIM against
// the ground truth, and keep at least 0.9x the keys' gradient energy.
TEST(Tcia, InBetweensBeatAdvectAndCrossfade) {
  constexpr int frames = 11, w = 48, h = 40;
  constexpr float speed = 2.0f, offset = 26.0f;
  TranslatingShot s(frames, w, h, speed, offset);
  const Image texture = smooth_noise(80, 64, 3, 9);
  std::vector<Image> truth;
  for (int t = 0; t < frames; ++t) {
    Image g(w, h, 3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) g.at(x, y, c) = texture.at(int(x - speed * t + offset), y + 8, c);
    truth.push_back(std::move(g));
  }
  s.shot.keys = {{0, truth[0].view(), {}}, {frames - 1, truth[frames - 1].view(), {}}};
  const std::vector<Image> out = stylize_shot(s.shot, fast_options());
  double ours = 0, crossfade = 0, energy = 0;
  for (int t = 1; t < frames - 1; ++t) {
    // The keys advected to frame t: key 0 forward, key 10 backward (whole pixels: exact where seen).
    Image blend(w, h, 3);
    const double a = double(frames - 1 - t) / (frames - 1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) {
          const float from_first = truth[0].at(std::clamp(int(x - speed * t), 0, w - 1), y, c);
          const float from_last = truth[frames - 1].at(std::clamp(int(x + speed * (frames - 1 - t)), 0, w - 1), y, c);
          blend.at(x, y, c) = float(a * from_first + (1 - a) * from_last);
        }
    ours += ssim(out[std::size_t(t)], truth[std::size_t(t)]) / (frames - 2);
    crossfade += ssim(blend, truth[std::size_t(t)]) / (frames - 2);
    energy += gradient_energy(out[std::size_t(t)]) / (frames - 2);
  }
  const double key_energy = (gradient_energy(truth[0]) + gradient_energy(truth[frames - 1])) / 2;
  RecordProperty("ssim", std::to_string(ours) + " vs crossfade " + std::to_string(crossfade));
  RecordProperty("gradient_energy", std::to_string(energy) + " vs keys " + std::to_string(key_energy));
  EXPECT_GT(ours, crossfade);
  EXPECT_GE(energy, 0.9 * key_energy);
}

TEST(Tcia, OutputIsAWarpOfTheExemplar) {
  const TranslatingShot s(3, 40, 32, 1.0f);
  const std::vector<Image> out = stylize_shot(s.shot, fast_options());
  // Centre output: every pixel is an exemplar pixel.
  for (const Image& frame : out)
    for (int y = 0; y < frame.height(); y += 3)
      for (int x = 0; x < frame.width(); x += 3) {
        bool found = false;
        for (int sy = 0; sy < s.style.height() && !found; ++sy)
          for (int sx = 0; sx < s.style.width() && !found; ++sx)
            found = frame.at(x, y, 0) == s.style.at(sx, sy, 0) && frame.at(x, y, 1) == s.style.at(sx, sy, 1);
        ASSERT_TRUE(found) << x << "," << y;
      }
}

TEST(Tcia, SameSeedSameShotForAnyThreadCount) {
  const TranslatingShot s(3, 40, 32, 1.0f);
  TciaOptions one = fast_options(), two = fast_options();
  one.synthesis.threads = 1;
  const auto a = stylize_shot(s.shot, one), b = stylize_shot(s.shot, two);
  for (std::size_t t = 0; t < a.size(); ++t)
    for (std::size_t i = 0; i < a[t].pixel_count() * 3; ++i) ASSERT_EQ(a[t].data()[i], b[t].data()[i]);
}

TEST(Tcia, BadShotsNameTheProblem) {
  const TranslatingShot s(2, 40, 32, 1.0f);
  Shot bad = s.shot;
  bad.frames[1].guides.clear();
  EXPECT_THROW(stylize_shot(bad, fast_options()), ValueError);
  bad = s.shot;
  bad.frames.clear();
  EXPECT_THROW(stylize_shot(bad, fast_options()), ValueError);
}

TEST(Tcia, KeysComeOutAsPaintedAndTheInBetweensFollowThem) {
  TranslatingShot s(8, 56, 40, 2.0f);
  // Keys at the first and last frame: the frame painted in a warmer palette.
  std::vector<Image> paintings;
  for (int k : {0, 7}) {
    Image p(56, 40, 3);
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 56; ++x) {
        const int sx = std::clamp(int(std::lround(x - 2.0f * k + 20)), 0, 79), sy = y + 8;
        p.at(x, y, 0) = std::min(1.0f, s.style.at(sx, sy, 0) + 0.4f);
        p.at(x, y, 1) = s.style.at(sx, sy, 1);
        p.at(x, y, 2) = 0.5f * s.style.at(sx, sy, 2);
      }
    paintings.push_back(std::move(p));
  }
  s.shot.keys = {{0, paintings[0].view(), {}}, {7, paintings[1].view(), {}}};
  const std::vector<Image> out = stylize_shot(s.shot, fast_options());
  for (int i : {0, 1}) {
    const Image& key = paintings[std::size_t(i)];
    const Image& frame = out[std::size_t(i == 0 ? 0 : 7)];
    for (std::size_t p = 0; p < key.pixel_count() * 3; ++p) ASSERT_NEAR(frame.data()[p], key.data()[p], 1.0f / 255);
  }
  // The in-betweens are painted like the keys (warm), not like the style.
  double red = 0, blue = 0;
  for (int t = 2; t <= 5; ++t)
    for (std::size_t p = 0; p < out[t].pixel_count(); ++p) red += out[t].data()[3 * p], blue += out[t].data()[3 * p + 2];
  EXPECT_GT(red, 2 * blue);
  // No pop into or out of a key: flicker there within 1.5x the median.
  std::vector<double> f;
  for (std::size_t t = 1; t < out.size(); ++t)
    f.push_back(flicker(out[t - 1].view(), out[t].view(), s.v_minus[t].view(), s.chi_minus[t].view()));
  { std::string all; for (double v : f) all += std::to_string(v) + " "; RecordProperty("flicker", all); }
  std::vector<double> sorted = f;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  EXPECT_LE(f.front(), 1.5 * median + 1e-4);
  EXPECT_LE(f.back(), 1.5 * median + 1e-4);
}

namespace {

// Eq. 8's shot: a flat target region (a sky, a wall) over an exemplar whose
// guide is flat only in a few small spots and mildly textured elsewhere, so
// that every target patch prefers the spots (Fig. 5's hotspots) while the
// rest of the exemplar fits almost as well.
struct HotspotShot {
  Image style, style_guide, target_guide;
  SynthesisInput input;
  HotspotShot(float texture) {
    style = smooth_noise(48, 48, 3, 5);
    style_guide = smooth_noise(48, 48, 1, 6);
    for (std::size_t i = 0; i < style_guide.pixel_count(); ++i)
      style_guide.data()[i] = 0.5f + texture * (style_guide.data()[i] - 0.5f);
    for (const auto [cx, cy] : {std::pair{12, 12}, std::pair{34, 30}})
      for (int y = cy - 4; y <= cy + 4; ++y)
        for (int x = cx - 4; x <= cx + 4; ++x) style_guide.at(x, y, 0) = 0.5f;
    target_guide = Image(40, 40, 1, 0.5f);
    input.style = style.view();
    input.guides.add("shade", style_guide.view(), target_guide.view(), 4.0f);
  }
};

// The peak of the usage of each exemplar pixel, blurred by a Gaussian of 2 px,
// in multiples of the fair use (target pixels per exemplar pixel).
double peak_blurred_usage(const SynthesisResult& r, int sw, int sh) {
  std::vector<double> use(std::size_t(sw) * sh, 0.0);
  for (int y = 0; y < r.image.height(); ++y)
    for (int x = 0; x < r.image.width(); ++x) {
      const ExemplarMatch m = r.match(x, y);
      use[std::size_t(std::clamp(int(m.y), 0, sh - 1)) * sw + std::clamp(int(m.x), 0, sw - 1)] += 1;
    }
  double peak = 0;
  for (int y = 0; y < sh; ++y)
    for (int x = 0; x < sw; ++x) {
      double s = 0, wsum = 0;
      for (int dy = -6; dy <= 6; ++dy)
        for (int dx = -6; dx <= 6; ++dx) {
          const double w = std::exp(-(dx * dx + dy * dy) / 8.0);
          wsum += w;
          if (x + dx >= 0 && x + dx < sw && y + dy >= 0 && y + dy < sh) s += w * use[std::size_t(y + dy) * sw + x + dx];
        }
      peak = std::max(peak, s / wsum);
    }
  const double fair = double(r.image.pixel_count()) / double(sw * sh);
  return peak / fair;
}

}  // namespace

// Fig. 5: on a flat target region over an exemplar with two attractive
// spots, the histogram (the method's h_s, h_tau and blur) spreads the usage:
// the peak of the blurred usage drops at least 2x, and the energy without
// the histogram term rises at most 1.1x. With usage none both are 1x.
TEST(Tcia, HistogramRemovesUsageHotspotsAtLittleEnergy) {
  HotspotShot s(0.05f);
  SynthesisOptions o = tcia_defaults();
  o.threads = 2;
  o.usage = PatchUsage::None;
  const SynthesisResult off = synthesize(s.input, o);
  const Solver judge(s.input, o);  // the energy without the histogram term
  o.usage = PatchUsage::Histogram;
  const SynthesisResult on = synthesize(s.input, o);
  const double peak_off = peak_blurred_usage(off, 48, 48), peak_on = peak_blurred_usage(on, 48, 48);
  const double e_off = judge.energy(0, off.field, off.image), e_on = judge.energy(0, on.field, on.image);
  RecordProperty("peak", std::to_string(peak_off) + " -> " + std::to_string(peak_on));
  RecordProperty("energy", std::to_string(e_off) + " -> " + std::to_string(e_on));
  EXPECT_GE(peak_off / peak_on, 2.0);
  EXPECT_LE(e_on / e_off, 1.1);
}

// StyLit per frame, the temporal guide and the resumable sequence job.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "tempera/app/contact_sheet.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/methods/stylit/stylit.hpp"
#include "tempera/methods/stylit/stylize_job.hpp"

using namespace tempera;
namespace fs = std::filesystem;

namespace {

constexpr int kW = 64, kH = 48;

double psnr(const Image& a, const Image& b, int border) {
  double se = 0;
  std::size_t n = 0;
  for (int y = border; y < a.height() - border; ++y)
    for (int x = border; x < a.width() - border; ++x)
      for (int c = 0; c < a.channels(); ++c, ++n) se += std::pow(a.at(x, y, c) - b.at(x, y, c), 2);
  return 10 * std::log10(1.0 / (se / double(n)));
}

Image noise(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Image img(w, h, 3);
  for (std::size_t i = 0; i < img.pixel_count() * 3; ++i) img.data()[i] = u(rng);
  return img;
}

// Linear light-path guides of a scene shifted right by `shift` pixels: a
// gradient plus a bright blob, so that guide values differ across the frame.
GuideFrame scene(double shift, int w = kW, int h = kH) {
  GuideFrame f;
  Image full(w, h, 3), lde(w, h, 3), lse(w, h, 3), ldde(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double u = x - shift, blob = std::exp(-(std::pow(u - w / 2.0, 2) + std::pow(y - h / 2.0, 2)) / 80.0);
      const float diffuse = float(0.1 + 0.8 * (u + w) / (3.0 * w) + 1.5 * blob), spec = float(2 * std::pow(blob, 8));
      const float indirect[3] = {0.1f * float(y) / h, 0.05f, 0.1f * (1 - float(y) / h)};
      for (int c = 0; c < 3; ++c) {
        lde.at(x, y, c) = diffuse * (1.0f - 0.25f * c);
        lse.at(x, y, c) = spec;
        ldde.at(x, y, c) = indirect[c];
        full.at(x, y, c) = lde.at(x, y, c) + spec + indirect[c];
      }
    }
  f.guides = {{"FULL", full}, {"LDE", lde}, {"LSE", lse}, {"LDDE", ldde}};
  return f;
}

// A painting of scene(0): coarse noise strokes whose brightness follows the shading.
Image painting_of(const GuideFrame& exemplar) {
  const Image shade = tonemap_guide(exemplar.get("FULL").view());
  Image strokes = noise(shade.width() / 4 + 1, shade.height() / 4 + 1, 11);
  Image out(shade.width(), shade.height(), 3);
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x)
      for (int c = 0; c < 3; ++c)
        out.at(x, y, c) = std::clamp(0.7f * shade.at(x, y, c) + 0.3f * strokes.at(x / 4, y / 4, c), 0.0f, 1.0f);
  return out;
}

StylitOptions fast(float temporal = 0) {
  StylitOptions o;
  o.temporal_weight = temporal;
  o.synthesis.threads = 2;
  return o;
}

// ---------------------------------------------------------------- files

Image uniform(int w, int h, int c, float v) { return Image(w, h, c, v); }

// A guide cache frame EXR as the Blender renderer writes it.
void write_cache_frame(const fs::path& folder, int frame, double shift, double speed) {
  GuideFrame g = scene(shift);
  g.guides["velocity_backward"] = uniform(kW, kH, 2, 0.0f);
  g.guides["occlusion_backward"] = uniform(kW, kH, 1, 1.0f);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) g.guides["velocity_backward"].at(x, y, 0) = float(speed);
    for (int x = 0; x < int(std::ceil(speed)); ++x) g.guides["occlusion_backward"].at(x, y, 0) = 0.0f;
  }
  const std::vector<std::pair<std::string, std::string>> layout = {
      {"FULL", "RGB"}, {"LDE", "RGB"}, {"LSE", "RGB"}, {"LDDE", "RGB"}, {"velocity_backward", "XY"},
      {"occlusion_backward", "V"}};
  Image all(kW, kH, 15);
  std::vector<std::string> names;
  for (const auto& [guide, components] : layout) {
    const Image& img = g.get(guide);
    for (int c = 0; c < img.channels(); ++c) {
      for (std::size_t i = 0; i < all.pixel_count(); ++i) all.data()[i * 15 + names.size()] = img.data()[i * img.channels() + c];
      names.push_back(guide + "." + components[c]);
    }
  }
  fs::create_directories(folder);
  char file[32];
  std::snprintf(file, sizeof file, "frame_%04d.exr", frame);
  write_image((folder / file).string(), all.view(), names);
}

struct JobFiles {
  fs::path root;
  JobFiles() {
    root = fs::temp_directory_path() / ("tempera_stylize_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root);
    for (int f = 1; f <= 3; ++f) write_cache_frame(root / "cache", f, 1.5 * (f - 1), 1.5);
    write_cache_frame(root / "exemplar", 1, 0.0, 0.0);
    write_image((root / "paint.png").string(), painting_of(scene(0)).view());
  }
  ~JobFiles() { fs::remove_all(root); }
  StylizeJobConfig config(const std::string& out = "out") const {
    StylizeJobConfig c;
    c.exemplar = (root / "paint.png").string();
    c.exemplar_guides = (root / "exemplar").string();
    c.guides = (root / "cache").string();
    c.frames = {1, 2, 3};
    c.out = (root / out).string();
    c.stylit = fast(0.5f);
    return c;
  }
};

std::vector<std::string> stray_files(const fs::path& folder) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    if (name.front() == '.' || name.find(".tmp") != std::string::npos) out.push_back(name);
  }
  return out;
}

bool same_pixels(const std::string& a, const std::string& b) {
  const Image x = read_image(a), y = read_image(b);
  return x.width() == y.width() && x.height() == y.height() && x.channels() == y.channels() &&
         std::equal(x.data(), x.data() + x.pixel_count() * x.channels(), y.data());
}

}  // namespace

TEST(Stylit, TonemapMatchesTheFormula) {
  Image linear(7, 1, 1);
  const float values[7] = {-1.0f, 0.0f, 0.002f, 0.5f, 4.0f, NAN, INFINITY};
  std::copy(values, values + 7, linear.data());
  const Image t = tonemap_guide(linear.view());
  auto expected = [](double x) {
    const double r = x / (1 + x);
    return r <= 0.0031308 ? 12.92 * r : 1.055 * std::pow(r, 1 / 2.4) - 0.055;
  };
  EXPECT_EQ(t.at(0, 0, 0), 0.0f);  // negative -> 0
  EXPECT_EQ(t.at(5, 0, 0), 0.0f);  // NaN -> 0
  for (int i : {1, 2, 3, 4}) EXPECT_NEAR(t.at(i, 0, 0), expected(values[i]), 1e-7) << values[i];
  EXPECT_NEAR(t.at(6, 0, 0), expected(1e6), 1e-7);
  EXPECT_LT(t.at(6, 0, 0), 1.0f);
}

TEST(Stylit, IdenticalGuidesReproduceTheStyle) {
  const Image style = noise(kW, kH, 7);
  GuideFrame g;  // coordinates as light: every patch of guide values is unique
  Image coords(kW, kH, 3);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) coords.at(x, y, 0) = float(x) / kW, coords.at(x, y, 1) = float(y) / kH;
  g.guides = {{"FULL", coords}, {"LDE", coords}, {"LSE", coords}, {"LDDE", coords}};
  StylitOptions o = fast();
  o.synthesis.usage = PatchUsage::None;
  const SynthesisResult r = stylize_frame(style.view(), g, g, nullptr, o);
  EXPECT_GT(psnr(r.image, style, 6), 30.0);  // the border band as in test_synthesis
}

TEST(Stylit, MissingOrUnknownGuidesAreNamed) {
  const GuideFrame ex = scene(0);
  GuideFrame target = scene(0);
  target.origin = "shot/frame_0004.exr";
  target.guides.erase("LDE");
  const Image style = painting_of(ex);
  try {
    stylize_frame(style.view(), ex, target, nullptr, fast());
    FAIL() << "no error";
  } catch (const ValueError& e) {
    EXPECT_NE(std::string(e.what()).find("guide 'LDE' missing from 'shot/frame_0004.exr'"), std::string::npos)
        << e.what();
  }
  StylitOptions o = fast();
  o.weights.push_back({"SSS", 1.0f});
  EXPECT_THROW(stylize_frame(style.view(), ex, ex, nullptr, o), ValueError);
  o = fast();
  for (auto& w : o.weights) w.second = 0;
  EXPECT_THROW(stylize_frame(style.view(), ex, ex, nullptr, o), ValueError);
}

// A translating scene: the temporal guide must cut the flicker (paint moving
// with the surface) without drifting away from the painting's colours.
TEST(Stylit, TemporalGuideReducesFlicker) {
  const GuideFrame ex = scene(0);
  const Image style = painting_of(ex);
  double style_mean = 0;
  for (std::size_t i = 0; i < style.pixel_count() * 3; ++i) style_mean += style.data()[i];
  style_mean /= double(style.pixel_count() * 3);
  const double speed = 1.0;
  Image velocity(kW, kH, 2, 0.0f), visible(kW, kH, 1, 1.0f);
  for (std::size_t i = 0; i < velocity.pixel_count(); ++i) velocity.data()[2 * i] = float(speed);
  for (int y = 0; y < kH; ++y) visible.at(0, y, 0) = 0.0f;  // entered from the left edge

  double flicker_by_weight[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    const StylitOptions o = fast(k == 0 ? 0.0f : 1.0f);
    Image previous;
    for (int t = 0; t < 6; ++t) {
      const TemporalInput temporal{previous.view(), velocity.view(), visible.view()};
      Image current = stylize_frame(style.view(), ex, scene(speed * t), previous.empty() ? nullptr : &temporal, o).image;
      if (!previous.empty()) flicker_by_weight[k] += flicker(previous.view(), current.view(), velocity.view(), visible.view()) / 5;
      double mean = 0;
      for (std::size_t i = 0; i < current.pixel_count() * 3; ++i) mean += current.data()[i];
      EXPECT_NEAR(mean / double(current.pixel_count() * 3), style_mean, 0.08) << "weight " << k << " frame " << t;
      previous = std::move(current);
    }
  }
  RecordProperty("flicker_temporal_0", std::to_string(flicker_by_weight[0]));
  RecordProperty("flicker_temporal_1", std::to_string(flicker_by_weight[1]));
  std::cout << "flicker: temporal 0 -> " << flicker_by_weight[0] << ", temporal 1 -> " << flicker_by_weight[1] << "\n";
  EXPECT_LT(flicker_by_weight[1], 0.7 * flicker_by_weight[0]);
}

TEST(Stylit, FlickerIsZeroForPaintMovingWithTheSurface) {
  const Image a = noise(20, 10, 1);
  Image b(20, 10, 3), v(20, 10, 2, 0.0f), vis(20, 10, 1, 1.0f);
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 20; ++x) {
      for (int c = 0; c < 3; ++c) b.at(x, y, c) = a.at(std::max(0, x - 2), y, c);
      v.at(x, y, 0) = 2;
      if (x < 2) vis.at(x, y, 0) = 0;
    }
  EXPECT_LT(flicker(a.view(), b.view(), v.view(), vis.view()), 1e-6);
  EXPECT_GT(flicker(a.view(), a.view(), v.view(), vis.view()), 0.2);
}

TEST(StylizeJob, RerunSkipsEverything) {
  JobFiles files;
  StylizeJob job(files.config());
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(job.run_frame(i).status, "stylized");
  StylizeJob again(files.config());
  for (std::size_t i = 0; i < 3; ++i) {
    const FrameResult r = again.run_frame(i);
    EXPECT_EQ(r.status, "skipped");
    EXPECT_EQ(r.path, (files.root / "out" / ("frame_000" + std::to_string(i + 1) + ".png")).string());
  }
}

TEST(StylizeJob, ResumeAfterCancelEqualsAnUninterruptedRun) {
  JobFiles files;
  StylizeJob straight(files.config("straight"));
  for (std::size_t i = 0; i < 3; ++i) straight.run_frame(i);

  StylizeJob interrupted(files.config("resumed"));
  interrupted.run_frame(0);
  int calls = 0;
  EXPECT_THROW(interrupted.run_frame(1, [&](double) { return ++calls < 2; }), CancelledError);
  const fs::path out = files.root / "resumed";
  EXPECT_TRUE(fs::exists(out / "frame_0001.png"));
  EXPECT_FALSE(fs::exists(out / "frame_0002.png"));
  EXPECT_TRUE(stray_files(out).empty());

  StylizeJob resumed(files.config("resumed"));
  EXPECT_EQ(resumed.run_frame(0).status, "skipped");
  EXPECT_EQ(resumed.run_frame(1).status, "stylized");
  EXPECT_EQ(resumed.run_frame(2).status, "stylized");
  for (const char* name : {"frame_0001.png", "frame_0002.png", "frame_0003.png"})
    EXPECT_TRUE(same_pixels((out / name).string(), (files.root / "straight" / name).string())) << name;
}

TEST(StylizeJob, ChangedWeightsOrInputsInvalidateTheKey) {
  JobFiles files;
  StylizeJob(files.config()).run_frame(0);
  StylizeJobConfig changed = files.config();
  changed.stylit.weights[1].second = 3.0f;
  EXPECT_EQ(StylizeJob(changed).run_frame(0).status, "stylized");
  EXPECT_EQ(StylizeJob(changed).run_frame(0).status, "skipped");
  changed.resume = false;
  EXPECT_EQ(StylizeJob(changed).run_frame(0).status, "stylized");
  // A newer painting file: same settings, new key.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  write_image((files.root / "paint.png").string(), painting_of(scene(0)).view());
  changed.resume = true;
  EXPECT_EQ(StylizeJob(changed).run_frame(0).status, "stylized");
}

TEST(StylizeJob, UnreadableReportMeansNothingDone) {
  JobFiles files;
  StylizeJob(files.config()).run_frame(0);
  std::ofstream(files.root / "out" / "tempera_stylize.json") << "{\n  \"format\": garbage";
  EXPECT_EQ(StylizeJob(files.config()).run_frame(0).status, "stylized");
  EXPECT_EQ(StylizeJob(files.config()).run_frame(0).status, "skipped");
}

TEST(StylizeJob, PaintingSizeIsCheckedAndResampledWhenTheAspectFits) {
  JobFiles files;
  write_image((files.root / "paint.png").string(), Image(2 * kW + 1, 2 * kH, 3, 0.5f).view());
  StylizeJob job(files.config());
  ASSERT_EQ(job.warnings().size(), 1u);
  EXPECT_NE(job.warnings()[0].find("resampled"), std::string::npos) << job.warnings()[0];
  EXPECT_EQ(read_image(job.run_frame(0).path).width(), kW);

  write_image((files.root / "paint.png").string(), Image(kW, kW, 3, 0.5f).view());
  try {
    StylizeJob bad(files.config());
    FAIL() << "no error";
  } catch (const ValueError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("64x64"), std::string::npos) << what;
    EXPECT_NE(what.find("64x48"), std::string::npos) << what;
  }
  Image nan_paint(kW, kH, 3, 0.5f);
  nan_paint.at(3, 4, 1) = NAN;
  write_image((files.root / "paint.exr").string(), nan_paint.view());
  StylizeJobConfig c = files.config();
  c.exemplar = (files.root / "paint.exr").string();
  EXPECT_THROW(StylizeJob{c}, ValueError);
}

TEST(StylizeJob, MissingInputsAreNamed) {
  JobFiles files;
  StylizeJobConfig c = files.config();
  c.frames = {1, 2, 9};
  try {
    StylizeJob job(c);
    FAIL() << "no error";
  } catch (const FileNotFoundError& e) {
    EXPECT_NE(std::string(e.what()).find("frame(s) 9"), std::string::npos) << e.what();
  }
  c = files.config();
  c.exemplar = (files.root / "none.png").string();
  EXPECT_THROW(StylizeJob{c}, FileNotFoundError);
  c = files.config();
  c.stylit.weights.back().second = 1.0f;  // LD12E, not in this cache
  EXPECT_THROW(StylizeJob{c}, ValueError);
}

TEST(ContactSheet, LayoutCentresAndBroadcasts) {
  const Image a(6, 4, 3, 1.0f), b(6, 4, 3, 2.0f), grey(2, 2, 1, 9.0f);
  ContactSheetLayout layout;
  layout.columns = 2;
  layout.gap = 3;
  layout.margin = 1;
  layout.background = {-1.0f};
  const Image sheet = contact_sheet({a.view(), b.view(), grey.view()}, layout);
  ASSERT_EQ(sheet.width(), 2 + 2 * 6 + 3);
  ASSERT_EQ(sheet.height(), 2 + 2 * 4 + 3);
  EXPECT_EQ(sheet.at(1, 1, 0), 1.0f);
  EXPECT_EQ(sheet.at(10, 1, 2), 2.0f);
  EXPECT_EQ(sheet.at(7, 1, 0), -1.0f);           // gap
  EXPECT_EQ(sheet.at(1 + 2, 8 + 1, 1), 9.0f);    // grey, centred in its cell, all channels
  EXPECT_EQ(sheet.at(1, 8, 0), -1.0f);
  EXPECT_THROW(contact_sheet({}), ValueError);
}

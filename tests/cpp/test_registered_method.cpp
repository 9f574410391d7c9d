// A method added at run time (methods/registry.hpp register_method) runs
// through `tempera stylize --method NAME` with no command, binding or panel
// code of its own: the example of docs/adding_a_method.md, "tint", shades each
// frame with the exemplar's mean colour by a guide's brightness.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "cli_args.hpp"
#include "tempera/app/file_keys.hpp"
#include "tempera/app/guide_cache.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/app/job_inputs.hpp"
#include "tempera/app/paths.hpp"
#include "tempera/app/record.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/methods/registry.hpp"

namespace fs = std::filesystem;
using namespace tempera;

namespace {

// --- the example method (docs/adding_a_method.md) ---------------------------

struct TintOptions {
  std::string guide = "FULL";  // --guide: the guide whose brightness shades the frame
  float strength = 1.0f;       // --strength: 0 = the guide as it is, 1 = fully tinted
};

TintOptions tint_options(const MethodOptions& given) {
  TintOptions o;
  for (const auto& [flag, text] : given) {
    if (flag == "guide") o.guide = text;
    else if (flag == "strength") o.strength = parse_number<float>(text, "--strength");
    else throw unknown_method_option("tint", flag);
  }
  if (!(o.strength >= 0 && o.strength <= 1)) throw ValueError(concat("--strength must be in [0, 1], got ", o.strength));
  return o;
}

class TintJob : public FrameJob {
 public:
  TintJob(const JobConfig& config, const MethodOptions& given) : config_(config), options_(tint_options(given)) {
    check_job_config(config_);
    const Image exemplar = read_image(config_.exemplar);
    for (std::size_t i = 0; i < exemplar.pixel_count(); ++i)
      for (int c = 0; c < 3; ++c)
        colour_[c] += exemplar.data()[i * exemplar.channels() + std::min(c, exemplar.channels() - 1)];
    for (float& c : colour_) c /= float(exemplar.pixel_count());
    inputs_.add_file(config_.exemplar, "exemplar");
    inputs_.add_folder(config_.guides, "guide cache", "the guides");
    inputs_.refuse_folder(config_.out);  // the core's rule: inputs are never written
  }
  const std::vector<int>& frames() const override { return config_.frames; }
  std::string output_path(int frame) const override {
    return (fs::path(config_.out) / frame_file("frame_", frame, config_.format)).string();
  }
  const JobInputs& inputs() const override { return inputs_; }

  FrameResult run_frame(std::size_t index, const ProgressCallback& progress) override {
    FrameResult r;
    r.frame = config_.frames.at(index);
    r.path = output_path(r.frame);
    const std::string guides = guide_cache_frame(config_.guides, r.frame);
    const std::string record = (fs::path(config_.out) / "tempera_tint" / frame_file("frame_", r.frame, "txt")).string();
    const std::string key = hash_hex(concat(options_.guide, " ", options_.strength, "\n", file_stamp(config_.exemplar),
                                            "\n", file_stamp(guides)));
    if (config_.resume && record_current(record, "tempera-tint 1", key, {r.path})) {  // the core's record
      r.status = "skipped";
      return r;
    }
    const GuideFrame frame = GuideFrame::read(guides, {options_.guide});
    const Image& g = frame.get(options_.guide);
    Image out(g.width(), g.height(), 3);
    for (int y = 0; y < g.height(); ++y)
      for (int x = 0; x < g.width(); ++x) {
        const float lum = (g.at(x, y, 0) + g.at(x, y, 1) + g.at(x, y, 2)) / 3;
        for (int c = 0; c < 3; ++c)
          out.at(x, y, c) = (1 - options_.strength) * g.at(x, y, c) + options_.strength * colour_[c] * lum;
      }
    if (progress && !progress(1.0)) throw CancelledError("cancelled");
    create_output_folder(fs::path(record).parent_path().string());  // at the first write: a refused job leaves nothing
    write_image(r.path, out.view());  // atomic, read back
    write_record(record, "tempera-tint 1", key, {r.path});
    r.status = "stylized";
    return r;
  }

 private:
  JobConfig config_;
  TintOptions options_;
  JobInputs inputs_;
  float colour_[3] = {0, 0, 0};
};

MethodEntry tint_entry() {
  MethodEntry m;
  m.name = "tint";
  m.title = "Tint (example)";
  m.summary = "Each frame shaded with the exemplar's mean colour by a guide's brightness";
  m.paper = "docs/adding_a_method.md";
  m.unit = "frame";
  m.docs = "docs/adding_a_method.md";
  m.make_job = [](const JobConfig& c, const MethodOptions& o) { return std::make_unique<TintJob>(c, o); };
  m.options_help =
      "  --guide NAME            the guide whose brightness shades the frame (default FULL)\n"
      "  --strength S            0 = the guide as it is, 1 = fully tinted (default 1)\n";
  return m;
}

// --- the test -------------------------------------------------------------------

struct Shot {
  fs::path root = fs::temp_directory_path() / concat("tempera_tint_", getpid());
  Shot() {
    fs::create_directories(root / "guides");
    Image paint(4, 4, 3);
    for (std::size_t i = 0; i < paint.pixel_count(); ++i) paint.data()[3 * i] = 1.0f;  // red
    write_image((root / "paint.png").string(), paint.view());
    for (int f = 1; f <= 2; ++f) {
      Image full(8, 6, 3);
      for (std::size_t i = 0; i < full.pixel_count() * 3; ++i) full.data()[i] = 0.5f;
      write_image(guide_cache_frame((root / "guides").string(), f), full.view(), {"FULL.R", "FULL.G", "FULL.B"});
    }
  }
  ~Shot() { fs::remove_all(root); }
  cli::Args args(const std::string& out, std::vector<std::string> extra = {}) const {
    cli::Args a = {"--method", "tint", "--guides", (root / "guides").string(), "--exemplar",
                   (root / "paint.png").string(), "--frames", "1-2", "--out", (root / out).string()};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
};

// Registers `entry` once per process (ctest runs each test alone, the test binary all together).
void register_once(const MethodEntry& entry) {
  if (std::none_of(method_registry().begin(), method_registry().end(),
                   [&](const MethodEntry& m) { return m.name == entry.name; }))
    register_method(entry);
}

}  // namespace

TEST(RegisteredMethod, RunsThroughTheOneCommandWithResumeAndNamedErrors) {
  register_once(tint_entry());
  EXPECT_THROW(register_method(tint_entry()), ValueError);  // a name once
  EXPECT_EQ(find_method("tint").unit, "frame");
  testing::internal::CaptureStdout();
  EXPECT_EQ(cli::run_stylize({"--help"}), 0);  // the --method list is the registry's
  const std::string help = testing::internal::GetCapturedStdout();
  EXPECT_NE(help.find("tint"), std::string::npos) << help;
  EXPECT_NE(help.find("tint          Tint (example)"), std::string::npos) << help;

  Shot shot;
  EXPECT_EQ(cli::run_stylize(shot.args("out", {"--strength", "1"})), 0);
  const Image made = read_image((shot.root / "out" / "frames" / "frame_0002.png").string());
  EXPECT_NEAR(made.at(3, 3, 0), 0.5f, 0.01f);  // red times the guide's brightness
  EXPECT_NEAR(made.at(3, 3, 1), 0.0f, 0.01f);
  testing::internal::CaptureStdout();
  const int again = cli::run_stylize(shot.args("out", {"--strength", "1"}));  // resumed: both current
  const std::string second = testing::internal::GetCapturedStdout();
  EXPECT_EQ(again, 0);
  EXPECT_NE(second.find("0 frame(s) stylized, 2 skipped"), std::string::npos) << second;

  EXPECT_THROW(cli::run_stylize(shot.args("bad", {"--strength", "2"})), ValueError);
  EXPECT_THROW(cli::run_stylize(shot.args("bad", {"--bogus", "1"})), ValueError);
  EXPECT_THROW(cli::run_stylize(shot.args("guides")), ValueError);  // would write into an input
}

namespace {

// The example as a light-path method: it takes the exemplar render's guides
// (and shades by FULL alone), so the one command gives it the exemplar
// scene, the video and the noise pass as it gives StyLit.
MethodEntry light_path_tint_entry() {
  MethodEntry m = tint_entry();
  m.name = "lighttint";
  m.light_path_guides = true;
  m.make_job = [](const JobConfig& c, const MethodOptions& given) {
    MethodOptions own;
    for (const auto& option : given)
      if (option.first != "exemplar-guides") own.push_back(option);
    return std::make_unique<TintJob>(c, own);
  };
  return m;
}

std::string error_of(const cli::Args& args) {
  try {
    cli::run_stylize(args);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(RegisteredMethod, ALightPathMethodGetsTheExemplarSceneAndTheNoisePass) {
  register_once(tint_entry());
  register_once(light_path_tint_entry());
  Shot shot;
  Image paint(64, 64, 3);  // big enough for the noise pass's pyramid
  for (std::size_t i = 0; i < paint.pixel_count() * 3; ++i) paint.data()[i] = float((i * 2654435761u) % 997) / 997;
  write_image((shot.root / "paint.png").string(), paint.view());
  const auto args = [&](const std::string& out, std::vector<std::string> extra) {
    cli::Args a = shot.args(out, std::move(extra));
    a[1] = "lighttint";
    return a;
  };
  EXPECT_NE(error_of(args("none", {})).find("give one of --exemplar-scene"), std::string::npos);
  const std::string guides = (shot.root / "guides").string();
  testing::internal::CaptureStdout();
  const int status = cli::run_stylize(args("out", {"--exemplar-guides", guides, "--noise", "1.3", "--no-video"}));
  const std::string said = testing::internal::GetCapturedStdout();
  EXPECT_EQ(status, 0) << said;
  EXPECT_TRUE(fs::is_regular_file(shot.root / "out" / "frames" / "frame_0002.png"));
  EXPECT_TRUE(fs::is_regular_file(shot.root / "out" / "noisy" / "frame_0002.png")) << said;  // boiled
  EXPECT_NE(said.find("noisy frame 2/2"), std::string::npos) << said;
  // The exemplar scene is rendered by Blender before the job: here there is none to run.
  setenv("TEMPERA_BLENDER", (shot.root / "no_blender").c_str(), 1);
  EXPECT_NE(error_of(args("scene", {"--exemplar-scene", (shot.root / "x.blend").string()})).find("scene file not found"),
            std::string::npos);
  unsetenv("TEMPERA_BLENDER");
  // A method that is not a light-path one has none of it, and a flag of another method says whose it is.
  EXPECT_NE(error_of(shot.args("bad", {"--noise", "1.3"})).find("unknown option '--noise' for --method tint"),
            std::string::npos);
  EXPECT_NE(error_of(shot.args("bad", {"--key", "1=k.png"})).find("--key needs --method tcia"), std::string::npos);
  EXPECT_NE(error_of(shot.args("bad", {"--temporal", "1"})).find("--temporal needs --method stylit"),
            std::string::npos);
}

TEST(RegisteredMethod, NamesMustBePlainAndNewAndAJobIsNeeded) {
  MethodEntry bad = tint_entry();
  bad.name = "Tint Me";
  EXPECT_THROW(register_method(bad), ValueError);
  bad.name = "stylit";
  EXPECT_THROW(register_method(bad), ValueError);
  bad.name = "segmentless";
  bad.unit = "segment";  // the segment unit runs a SegmentJob: a frame job factory is not one
  EXPECT_THROW(register_method(bad), ValueError);
  bad.name = "jobless";
  bad.unit = "frame";
  bad.make_job = nullptr;
  EXPECT_THROW(register_method(bad), ValueError);
}

TEST(RegisteredMethod, TheCoherentMethodIsASegmentJobOfTheOneCommand) {
  const MethodEntry& tcia = find_method("tcia");
  EXPECT_EQ(tcia.unit, "segment");
  EXPECT_TRUE(tcia.make_segment_job && !tcia.make_job);
  EXPECT_NE(tcia.options_help.find("--segment A-B"), std::string::npos);
  JobConfig config;  // the options are read before any file
  config.exemplar = "nowhere.png", config.guides = "nowhere", config.frames = {1, 2}, config.out = "nowhere_out";
  try {
    make_method_segment_job(tcia, config, {{"segment", "3"}});
    FAIL() << "--segment 3 is no segment";
  } catch (const ValueError& e) {
    EXPECT_NE(std::string(e.what()).find("--segment expects A-B"), std::string::npos) << e.what();
  }
  EXPECT_THROW(make_method_job(tcia, config, {}), ValueError);  // not a frame job
  EXPECT_FALSE(fs::exists("nowhere_out"));
}

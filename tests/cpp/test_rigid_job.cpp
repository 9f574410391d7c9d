// The rigid-body method as a job of the registry (rigid_job.hpp): its files
// (tracks.json, manifest.json, exemplar folders) read and checked, frames
// made, resumed and cancelled like every method's; and the small JSON
// reader and writer the tracks go through (app/json.hpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "tempera/app/file_keys.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/app/json.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/methods/rigid/rigid_exemplar.hpp"
#include "tempera/methods/rigid/rigid_job.hpp"
#include "tempera/methods/rigid/tracks_file.hpp"

namespace fs = std::filesystem;
using namespace tempera;

namespace {

struct Folder {
  fs::path root = fs::temp_directory_path() / concat("tempera_rigid_job_", getpid(), "_",
                                                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
  Folder() { fs::remove_all(root), fs::create_directories(root); }
  ~Folder() { fs::remove_all(root); }
};

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A guide cache of a ball thrown to the left: tracks.json and manifest.json.
std::string make_cache(const fs::path& root) {
  const fs::path cache = root / "cache";
  if (fs::exists(cache / kTracksName)) return cache.string();  // a test may have added to it
  TracksFile tracks;
  tracks.gravity = {0, 1.0};
  tracks.objects["Target"] = bouncing_ball({200, 30}, {-3.0, 0}, 14, 1.0, 150, 0.7, -0.05, 24);
  write_tracks_file(cache.string(), tracks);
  write_text(cache / "manifest.json", R"({"resolution": [240, 160]})");
  return cache.string();
}

// A small drawn exemplar: a ball thrown to the right, 30 frames drawn by the generator.
std::string make_exemplar(const fs::path& root) {
  const fs::path folder = root / "exemplar";
  if (fs::exists(folder)) return folder.string();  // as drawn: its files' times are in the frames' key
  TracksFile tracks;
  tracks.gravity = {0, 1.2};
  tracks.objects["Ball"] = bouncing_ball({30, 40}, {4.0, 0}, 15, 1.2, 150, 0.6, 0.05, 30);
  fs::create_directories(folder / "drawn");
  for (int f = 0; f < 30; ++f)
    write_image((folder / "drawn" / frame_file("", f + 1, "png")).string(),
                draw_exemplar_frame(tracks.objects["Ball"], f, ExemplarStyle{}, 240, 160).view());
  write_tracks_file(folder.string(), tracks);
  return folder.string();
}

RigidJobConfig config_for(const fs::path& root) {
  RigidJobConfig c;
  c.guides = make_cache(root);
  c.exemplar = make_exemplar(root);
  c.frames = {3, 4, 5};
  c.out = (root / "out" / "frames").string();
  c.options.k = 2;
  return c;
}

}  // namespace

TEST(Json, ReadsWhatPythonWritesAndNamesWhereItIsMalformed) {
  const Json v = parse_json(R"({"a": [1, 2.5, -3e2, true, null], "b": "x\"\u00e9\ud83d\ude00", "a": {}})");
  ASSERT_EQ(v.type, Json::Type::Object);
  ASSERT_EQ(v.fields.size(), 2u);  // the last "a" wins, as in Python
  EXPECT_EQ(v.find("a")->type, Json::Type::Object);
  EXPECT_EQ(v.find("b")->text, "x\"\xc3\xa9\xf0\x9f\x98\x80");
  const Json list = parse_json("[1, 2.5, -3e2, NaN]");
  EXPECT_TRUE(list.items[0].integer);
  EXPECT_FALSE(list.items[1].integer);
  EXPECT_EQ(list.items[2].number, -300);
  EXPECT_TRUE(std::isnan(list.items[3].number));
  try {
    parse_json("{\"a\": 1,\n \"b\": }");
    FAIL();
  } catch (const ValueError& e) {
    EXPECT_STREQ(e.what(), "line 2 column 7: expected a value");
  }
  EXPECT_THROW(parse_json(std::string(1000, '[') + std::string(1000, ']')), ValueError);  // no stack overflow
  EXPECT_THROW(parse_json("[1] x"), ValueError);
  EXPECT_THROW(parse_json("[01]"), ValueError);
}

TEST(Json, NumbersReadBackExactly) {
  const std::vector<double> values = {0.1, 1.0 / 3.0, -2.5e-300, 1e21, 60, 123456789.123456789};
  std::vector<Json> items;
  for (double x : values) items.push_back(Json::of(x));
  const Json back = parse_json(write_json(Json::array(items)));
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(back.items[i].number, values[i]);
}

TEST(TracksFile, WrittenTracksReadBackAndBadOnesAreNamed) {
  Folder f;
  const std::string cache = make_cache(f.root);
  const TracksFile tracks = read_tracks_file(cache);
  const Track made = bouncing_ball({200, 30}, {-3.0, 0}, 14, 1.0, 150, 0.7, -0.05, 24);
  ASSERT_EQ(tracks.objects.at("Target").frames.size(), made.frames.size());
  EXPECT_EQ(tracks.objects.at("Target").frames[7].centre.x, made.frames[7].centre.x);
  EXPECT_EQ(tracks.objects.at("Target").events.size(), made.events.size());
  EXPECT_EQ(guide_cache_frame_size(cache), std::make_pair(240, 160));
  const auto message = [&](const std::string& text) {
    write_text(fs::path(cache) / kTracksName, text);
    try {
      read_tracks_file(cache);
    } catch (const ValueError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(R"({"format": 2, "objects": {}})").find("not a tracks file of format 1"), std::string::npos);
  EXPECT_NE(message(R"({"format": 1, "frame_start": 1.5, "gravity": [0, 1], "objects": {}})").find("frame_start must"),
            std::string::npos);
  EXPECT_NE(message(R"({"format": 1, "frame_start": 1, "gravity": [0, NaN], "objects": {}})").find("gravity must"),
            std::string::npos);
  EXPECT_NE(message(R"({"format": 1, "frame_start": 1, "gravity": [0, 1], "objects": {"Ball": {"centre": []}}})")
                .find("object 'Ball': a track needs 'velocity'"),
            std::string::npos);
  EXPECT_NE(message("{").find("unreadable tracks (line 1 column 2"), std::string::npos);
  fs::remove(fs::path(cache) / kTracksName);
  EXPECT_THROW(read_tracks_file(cache), FileNotFoundError);
  write_text(fs::path(cache) / "manifest.json", R"({"resolution": [240]})");
  EXPECT_THROW(guide_cache_frame_size(cache), ValueError);
}

TEST(RigidJob, DrawsResumesAndRedrawsForOtherSettings) {
  Folder f;
  RigidJob job(config_for(f.root));
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(job.run_frame(i).status, "stylized");
  const Image frame = read_image(job.output_path(4));
  ASSERT_EQ(frame.channels(), 4);
  float ink = 0;
  for (std::size_t i = 0; i < frame.pixel_count(); ++i) ink = std::max(ink, frame.data()[4 * i + 3]);
  EXPECT_GT(ink, 0.5f);  // the ball is drawn
  RigidJob again(config_for(f.root));
  EXPECT_EQ(again.run_frame(1).status, "skipped");
  fs::remove(again.output_path(4));
  EXPECT_EQ(again.run_frame(1).status, "stylized");
  RigidJobConfig other = config_for(f.root);
  other.options.k = 1;
  EXPECT_EQ(RigidJob(other).run_frame(0).status, "stylized");  // other settings: made again
}

TEST(RigidJob, CancelWritesNothingAndBadInputIsNamed) {
  Folder f;
  RigidJob job(config_for(f.root));
  EXPECT_THROW(job.run_frame(0, [](double) { return false; }), CancelledError);
  EXPECT_FALSE(fs::exists(job.output_path(3)));
  // Esc while the exemplar is fitted (the first frame's long part): the fit
  // hears it between drawings; nothing is written, and the frame made
  // afterwards is an uninterrupted run's.
  std::vector<double> heard;
  EXPECT_THROW(job.run_frame(0, [&](double fraction) {
    heard.push_back(fraction);
    return heard.size() < 3;
  }), CancelledError);
  ASSERT_EQ(heard.size(), 3u);
  EXPECT_GT(heard[2], heard[1]);
  EXPECT_LT(heard[2], 0.9);  // within the fit, not after it
  EXPECT_FALSE(fs::exists(job.output_path(3)));
  EXPECT_EQ(job.run_frame(0).status, "stylized");
  RigidJobConfig whole = config_for(f.root);
  whole.out = (f.root / "whole").string();
  RigidJob uninterrupted(whole);
  uninterrupted.run_frame(0);
  EXPECT_EQ(read_file(job.output_path(3)), read_file(uninterrupted.output_path(3)));
  RigidJobConfig outside = config_for(f.root);
  outside.frames = {24, 25};
  try {
    RigidJob{outside};
    FAIL();
  } catch (const ValueError& e) {
    EXPECT_STREQ(e.what(), "frame 25 is outside the tracked frames 1-24");
  }
  RigidJobConfig onto_guides = config_for(f.root);
  onto_guides.out = onto_guides.guides;
  EXPECT_THROW(RigidJob{onto_guides}, ValueError);  // never writes into its inputs
  RigidJobConfig no_drawings = config_for(f.root);
  no_drawings.exemplar = (f.root / "cache").string();  // tracks but nothing drawn
  EXPECT_THROW(RigidJob{no_drawings}, FileNotFoundError);
}

TEST(RigidJob, EveryTrackedObjectIsDrawnAndLaidFarToNear) {
  Folder f;
  RigidJobConfig one = config_for(f.root);  // writes the cache; a second ball joins it
  TracksFile tracks = read_tracks_file(one.guides);
  tracks.objects["Second"] = bouncing_ball({40, 30}, {3.0, 0}, 12, 1.0, 150, 0.7, 0.05, 24);
  tracks.depths["Target"] = std::vector<double>(24, 5.0);
  tracks.depths["Second"] = std::vector<double>(24, 9.0);
  write_tracks_file(one.guides, tracks);
  EXPECT_EQ(read_tracks_file(one.guides).depths.at("Second")[3], 9.0);
  RigidJobConfig both = config_for(f.root);
  both.out = (f.root / "both").string();
  RigidJob all(both);  // no object named: every one
  const auto alpha = [](const std::string& path) {
    const Image image = read_image(path);
    std::vector<float> a(image.pixel_count());
    for (std::size_t i = 0; i < a.size(); ++i) a[i] = image.data()[4 * i + 3];
    return a;
  };
  all.run_frame(0);
  std::vector<std::vector<float>> alone;
  for (const char* name : {"Target", "Second"}) {
    RigidJobConfig c = config_for(f.root);
    c.objects = {name};
    c.out = (f.root / name).string();
    RigidJob job(c);
    job.run_frame(0);
    alone.push_back(alpha(job.output_path(3)));
  }
  const std::vector<float> composite = alpha(all.output_path(3));
  double ink_a = 0, ink_b = 0;
  for (std::size_t i = 0; i < composite.size(); ++i) {
    const float expected = 1 - (1 - alone[0][i]) * (1 - alone[1][i]);  // either ball's ink, over the other
    ASSERT_NEAR(composite[i], expected, 2.5f / 255) << i;
    ink_a += alone[0][i], ink_b += alone[1][i];
  }
  EXPECT_GT(ink_a, 50);
  EXPECT_GT(ink_b, 50);  // both balls are in the frame
  RigidJobConfig unknown = config_for(f.root);
  unknown.objects = {"Third"};
  EXPECT_THROW(RigidJob{unknown}, ValueError);
}

// The job core's shared frame report (app/frame_report.hpp): entries added by
// several writers of one folder merge; a frame is current only with its key
// and the very file written; a damaged report is set aside, never trusted.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "tempera/app/frame_report.hpp"

namespace fs = std::filesystem;
using namespace tempera;

namespace {

struct Folder {
  fs::path root = fs::temp_directory_path() / ("tempera_frame_report_" + std::to_string(getpid()));
  Folder() { fs::create_directories(root); }
  ~Folder() { fs::remove_all(root); }
  std::string file(const std::string& name, const std::string& text) const {
    std::ofstream((root / name).string(), std::ios::binary) << text;
    return (root / name).string();
  }
};

ReportedFrame entry(const std::string& key, const std::string& path) {
  return {key, fs::path(path).filename().string(), 0.01, 0.9, file_digest(path)};
}

}  // namespace

TEST(FrameReport, WritersOfOneFolderMergeAndOnlyTheWrittenFileIsCurrent) {
  Folder f;
  const FrameReport a(f.root.string(), "report.json", "test-report 1"), b(f.root.string(), "report.json",
                                                                          "test-report 1");
  std::vector<std::string> warnings;
  const std::string one = f.file("frame_0001.png", "one"), two = f.file("frame_0002.png", "two");
  a.add(1, entry("k1", one), "settings", warnings);
  b.add(2, entry("k2", two), "settings", warnings);  // another process: both frames stay
  ASSERT_TRUE(a.current(1, "k1", one, warnings).has_value());
  ASSERT_TRUE(a.current(2, "k2", two, warnings).has_value());
  EXPECT_DOUBLE_EQ(a.current(1, "k1", one, warnings)->source_coverage, 0.9);
  EXPECT_FALSE(a.current(1, "other settings", one, warnings).has_value());
  f.file("frame_0002.png", "tw");  // truncated or replaced since: made again
  EXPECT_FALSE(a.current(2, "k2", two, warnings).has_value());
  EXPECT_FALSE(a.current(3, "k3", one, warnings).has_value());
  EXPECT_TRUE(warnings.empty());
}

TEST(FrameReport, ADamagedOrForeignReportIsSetAsideAndNothingIsCurrent) {
  Folder f;
  const FrameReport report(f.root.string(), "report.json", "test-report 1");
  std::vector<std::string> warnings;
  const std::string one = f.file("frame_0001.png", "one");
  report.add(1, entry("k1", one), "settings", warnings);
  const FrameReport newer(f.root.string(), "report.json", "test-report 2");  // another version's format
  EXPECT_FALSE(newer.current(1, "k1", one, warnings).has_value());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("set aside"), std::string::npos) << warnings[0];
  int aside = 0;
  for (const auto& e : fs::directory_iterator(f.root)) aside += e.path().filename().string().find(".corrupt-") != std::string::npos;
  EXPECT_EQ(aside, 1);
  f.file("report.json", "{\n  \"format\": \"test-report 1\",\n  \"frames\": {\n    \"1\": {\"key\": \"k1\"");  // cut short
  EXPECT_FALSE(report.current(1, "k1", one, warnings).has_value());
  EXPECT_EQ(warnings.size(), 2u);
}

// Images kept in an unnamed file the kernel can page out (app/scratch_images.hpp):
// the coherent method's per-frame inputs.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "tempera/app/scratch_images.hpp"
#include "tempera/engine/error.hpp"

using namespace tempera;
namespace fs = std::filesystem;

namespace {

fs::path fresh_folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / concat("tempera_scratch_", name, "_", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Image ramp(int w, int h, int c, float start) {
  Image image(w, h, c);
  for (std::size_t i = 0; i < image.pixel_count() * std::size_t(c); ++i) image.data()[i] = start + 0.37f * float(i);
  return image;
}

// The line of /proc/self/maps whose range holds `address` ("" if none).
std::string mapping_of(const void* address) {
  std::ifstream maps("/proc/self/maps");
  const auto a = reinterpret_cast<std::uintptr_t>(address);
  for (std::string line; std::getline(maps, line);) {
    const std::uintptr_t lo = std::stoull(line.substr(0, line.find('-')), nullptr, 16);
    const std::uintptr_t hi = std::stoull(line.substr(line.find('-') + 1, line.find(' ')), nullptr, 16);
    if (a >= lo && a < hi) return line;
  }
  return "";
}

}  // namespace

TEST(ScratchImages, KeepsTheSameFloatsInAnUnnamedFileOfTheFolder) {
  const fs::path dir = fresh_folder("keeps");
  {
    ScratchImages scratch(dir.string());
    // A temporary folder on a file system without O_TMPFILE (overlayfs before
    // Linux 6.6) leaves the job in plain memory, as designed: nothing to test here.
    if (!scratch.disk_backed()) GTEST_SKIP() << dir << "'s file system has no O_TMPFILE";
    // Sizes that are not whole pages, one after another in the file.
    const Image a = ramp(37, 11, 3, 0.5f), b = ramp(5, 3, 1, -2.0f), c = ramp(640, 480, 2, 1e3f);
    const ImageView va = scratch.add(a), vb = scratch.add(b), vc = scratch.add(c);
    for (const auto& [view, image] : {std::pair{va, &a}, std::pair{vb, &b}, std::pair{vc, &c}}) {
      EXPECT_EQ(view.width, image->width());
      EXPECT_EQ(view.height, image->height());
      EXPECT_EQ(view.channels, image->channels());
      EXPECT_EQ(std::memcmp(view.data, image->data(), view.size() * sizeof(float)), 0);
      // File-backed pages (what the kernel can write back and drop), of a
      // file in the folder that has no name there.
      const std::string line = mapping_of(view.data);
      EXPECT_NE(line.find(dir.string()), std::string::npos) << line;
      EXPECT_NE(line.find("(deleted)"), std::string::npos) << line;
    }
    EXPECT_GE(scratch.bytes(), (a.pixel_count() * 3 + b.pixel_count() + c.pixel_count() * 2) * sizeof(float));
    EXPECT_TRUE(fs::is_empty(dir));  // nothing to see, nothing to clean up
  }
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST(ScratchImages, AMissingFolderIsAnIoErrorNamingIt) {
  const fs::path dir = fs::temp_directory_path() / concat("tempera_scratch_missing_", ::getpid());
  fs::remove_all(dir);
  try {
    ScratchImages scratch(dir.string());
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.string()), std::string::npos) << e.what();
  }
}

TEST(ScratchImages, EmptyImagesNeedNoSpace) {
  const fs::path dir = fresh_folder("empty");
  ScratchImages scratch(dir.string());
  const ImageView v = scratch.add(Image());
  EXPECT_TRUE(v.empty());
  EXPECT_EQ(scratch.bytes(), 0u);
  fs::remove_all(dir);
}

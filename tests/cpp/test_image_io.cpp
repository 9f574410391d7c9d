#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tempera/engine/error.hpp"
#include "tempera/app/image_io.hpp"

namespace fs = std::filesystem;
using namespace tempera;

namespace {

fs::path scratch_dir() {
  fs::path dir = fs::temp_directory_path() / ("tempera_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

Image gradient(int w, int h, int c) {
  Image img(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) img.at(x, y, k) = float(x + 2 * y + k) / float(w + 2 * h + c);
  return img;
}

}  // namespace

TEST(ImageIo, ExrRoundTripKeepsFloatsAndNames) {
  const fs::path path = scratch_dir() / "round.exr";
  Image img = gradient(7, 5, 3);
  img.at(2, 3, 1) = 12.5f;  // HDR value survives
  write_image(path.string(), img.view(), {"Combined.R", "Combined.G", "Vector.X"});
  Image back = read_image(path.string());
  ASSERT_EQ(back.width(), 7);
  ASSERT_EQ(back.height(), 5);
  ASSERT_EQ(back.channels(), 3);
  EXPECT_FLOAT_EQ(back.at(2, 3, 1), 12.5f);
  // OIIO orders EXR channels; select by name, never by position.
  Image vx = read_image(path.string(), {"Vector.X", "Combined.R"});
  ASSERT_EQ(vx.channels(), 2);
  EXPECT_FLOAT_EQ(vx.at(4, 1, 0), img.at(4, 1, 2));
  EXPECT_FLOAT_EQ(vx.at(4, 1, 1), img.at(4, 1, 0));
}

TEST(ImageIo, PngRoundTripQuantizesTo8Bit) {
  const fs::path path = scratch_dir() / "round.png";
  Image img = gradient(9, 4, 4);
  write_image(path.string(), img.view());
  Image back = read_image(path.string());
  ASSERT_EQ(back.channels(), 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 9; ++x)
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(back.at(x, y, c), img.at(x, y, c), 0.5 / 255 + 1e-6);
}

TEST(ImageIo, MissingFileNamesTheFile) {
  try {
    read_image("/nonexistent/folder/missing.png");
    FAIL() << "no exception";
  } catch (const FileNotFoundError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos);
  }
}

TEST(ImageIo, CorruptFileNamesTheFile) {
  const fs::path path = scratch_dir() / "corrupt.png";
  std::ofstream(path) << "this is not a png";
  try {
    read_image(path.string());
    FAIL() << "no exception";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("corrupt.png"), std::string::npos);
  }
}

TEST(ImageIo, MissingChannelIsValueError) {
  const fs::path path = scratch_dir() / "chan.exr";
  write_image(path.string(), gradient(3, 3, 1).view(), {"Depth.Z"});
  EXPECT_THROW(read_image(path.string(), {"Vector.X"}), ValueError);
}

TEST(ImageIo, WriteLeavesNoTemporaryFiles) {
  const fs::path dir = scratch_dir() / "atomic";
  fs::create_directories(dir);
  write_image((dir / "a.png").string(), gradient(4, 4, 3).view());
  write_image((dir / "b.exr").string(), gradient(4, 4, 3).view());
  int count = 0;
  for (auto& entry : fs::directory_iterator(dir)) {
    ++count;
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos);
  }
  EXPECT_EQ(count, 2);
}

TEST(ImageIo, UnknownExtensionIsIoError) {
  EXPECT_THROW(write_image((scratch_dir() / "x.notaformat").string(), gradient(2, 2, 1).view()), IoError);
}

TEST(ImageIo, ReadsOneLayerOfAMultilayerFile) {
  const fs::path path = scratch_dir() / "layers.exr";
  write_image(path.string(), gradient(5, 4, 4).view(), {"FULL.R", "FULL.G", "FULL.B", "lines.V"});
  const Image full = read_image_layer(path.string(), "FULL");
  EXPECT_EQ(full.channels(), 3);
  const Image lines = read_image_layer(path.string(), "lines");
  EXPECT_EQ(lines.channels(), 1);
  try {
    read_image_layer(path.string(), "LDE");
    FAIL();
  } catch (const ValueError& e) {
    EXPECT_NE(std::string(e.what()).find("it has: FULL, lines"), std::string::npos) << e.what();
  }
}

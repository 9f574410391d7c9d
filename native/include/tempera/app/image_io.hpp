#pragma once
// Reading and writing images through OpenImageIO: PNG, JPEG, TIFF, EXR (and
// whatever else OIIO knows). Multilayer EXR channels are selected by name.
#include <cstdint>
#include <string>
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

struct ImageFileInfo {
  int width = 0;
  int height = 0;
  std::vector<std::string> channel_names;
};

// Images whose header declares more pixels than this are refused (IoError)
// before any pixel memory is allocated: a 74-byte PNG can declare 12000².
// 50 Mpix by default (8K UHD fits); TEMPERA_MAX_IMAGE_PIXELS or
// set_max_image_pixels() (CLI --max-image-pixels) change it.
constexpr std::int64_t kDefaultMaxImagePixels = 50'000'000;
// Pixels count with up to this many channels: more channels spend the limit
// faster (the decoded floats may take at most max_image_pixels() x 8 x 4 bytes,
// 1.6 GB by default; a 4K guide frame with its 35 standard channels is 1.16 GB).
constexpr int kMaxImageChannelsPerPixel = 8;
std::int64_t max_image_pixels();
void set_max_image_pixels(std::int64_t pixels);

// ".<stem>.tmp<pid>-<16 random hex digits><extension>": a temporary file name
// no other process writing into the same folder picks (even one with the same
// process ID, as in containers).
std::string temporary_name(const std::string& stem, const std::string& extension);

// Size and channel names of an image file without reading its pixels.
ImageFileInfo inspect_image(const std::string& path);

// Reads `path` as float. With `channels` empty all channels are read; otherwise
// exactly the named channels, in the given order (FileNotFoundError / IoError /
// ValueError naming the file and the missing channel on failure).
Image read_image(const std::string& path, const std::vector<std::string>& channels = {});

// The channels of one layer of `path`: the channel named `layer` itself, or
// every channel named "<layer>.<component>" in file order (e.g. "FULL" gives
// FULL.R, FULL.G, FULL.B of a guide cache frame). ValueError lists the layers
// the file has when there is no such layer.
Image read_image_layer(const std::string& path, const std::string& layer);

// Writes atomically: a temporary file in the same folder, read back whole,
// then a rename, so a crash, a cancel or a full disk never leaves a
// half-written `path` (IoError, and the earlier file stays). 8-bit formats (PNG, JPEG)
// get values clamped to [0, 1]; EXR and TIFF keep float.
void write_image(const std::string& path, const ImageView& image,
                 const std::vector<std::string>& channel_names = {});

// `image` resampled to width x height with OIIO's default filter for the
// scale (a good downsampling filter, not point sampling). Any channel count.
Image resize_image(const ImageView& image, int width, int height);

}  // namespace tempera

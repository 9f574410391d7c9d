#include "tempera/app/image_io.hpp"

#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <random>
#include <thread>
#include <unistd.h>

#include "tempera/engine/error.hpp"

namespace fs = std::filesystem;

namespace tempera {
namespace {

std::int64_t initial_max_image_pixels() {
  // TEMPERA_MAX_IMAGE_PIXELS raises (or lowers) the cap for every entry point.
  if (const char* env = std::getenv("TEMPERA_MAX_IMAGE_PIXELS"); env && *env) {
    std::int64_t value = 0;
    const auto [end, ec] = std::from_chars(env, env + std::strlen(env), value);
    if (ec == std::errc() && *end == 0 && value > 0) return value;
  }
  return kDefaultMaxImagePixels;
}

std::atomic<std::int64_t>& pixel_cap() {
  static std::atomic<std::int64_t> cap{initial_max_image_pixels()};
  return cap;
}

// The declared size, checked before any pixel memory is allocated: a few
// bytes of header can declare gigabytes.
void check_declared_size(const std::string& path, const OIIO::ImageSpec& spec) {
  const std::int64_t cap = pixel_cap().load();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw IoError(concat("image '", path, "' declares an empty size ", spec.width, "x", spec.height, " with ",
                         spec.nchannels, " channels"));
  const char* raise = "; raise it with TEMPERA_MAX_IMAGE_PIXELS, --max-image-pixels or "
                      "tempera.set_max_image_pixels() if the file is real";
  const std::int64_t pixels = std::int64_t(spec.width) * spec.height;
  if (pixels > cap || spec.nchannels > 4096)
    throw IoError(concat("image '", path, "' declares ", spec.width, "x", spec.height, " pixels (", spec.nchannels,
                         " channels), more than the limit of ", cap, " pixels", raise));
  // Reading decodes a whole part into floats: bytes, not pixels, are what a
  // header with many channels costs (a 135-byte TIFF can declare 1000x500
  // pixels of 1024 channels, 2 GB).
  const auto bytes = static_cast<unsigned __int128>(pixels) * unsigned(spec.nchannels) * sizeof(float);
  const auto budget = static_cast<unsigned __int128>(cap) * kMaxImageChannelsPerPixel * sizeof(float);
  if (bytes > budget)
    throw IoError(concat("image '", path, "' declares ", spec.width, "x", spec.height, " pixels of ", spec.nchannels,
                         " channels, ", std::int64_t(bytes / 1'000'000), " MB decoded, more than the limit of ",
                         std::int64_t(budget / 1'000'000), " MB (", cap, " pixels of up to ",
                         kMaxImageChannelsPerPixel, " channels)", raise));
}

// A random part for temporary names: process IDs repeat across containers.
std::string random_tag() {
  static thread_local std::mt19937_64 rng{std::random_device{}() ^
                                          (std::uint64_t(getpid()) << 32) ^
                                          std::uint64_t(std::hash<std::thread::id>{}(std::this_thread::get_id()))};
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(rng()));
  return text;
}

std::unique_ptr<OIIO::ImageInput> open_input(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory)  // e.g. a folder on the way that may not be entered
    throw IoError(concat("cannot read image '", path, "': ", ec.message()));
  if (!fs::exists(status)) throw FileNotFoundError(concat("image file not found: '", path, "'"));
  if (fs::is_directory(status)) throw IoError(concat("'", path, "' is a folder, not an image file"));
  if (access(path.c_str(), R_OK) != 0)
    throw IoError(concat("cannot read image '", path, "': ", std::strerror(errno)));
  // Keep alpha as stored (straight): guides and exemplars are data, not
  // compositing layers, and must not be premultiplied behind our back.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto input = OIIO::ImageInput::open(path, &config);
  if (!input) {
    std::string why = OIIO::geterror();
    throw IoError(concat("cannot read image '", path, "': ", why.empty() ? "unknown format" : why));
  }
  for (int sub = 0; input->seek_subimage(sub, 0); ++sub) check_declared_size(path, input->spec());
  input->seek_subimage(0, 0);
  return input;
}

// Where each channel lives: multi-part EXR files spread channels over subimages.
struct ChannelLocation {
  int subimage;
  int index;
};

std::vector<std::pair<std::string, ChannelLocation>> channel_map(OIIO::ImageInput& input) {
  std::vector<std::pair<std::string, ChannelLocation>> map;
  for (int sub = 0; input.seek_subimage(sub, 0); ++sub) {
    const auto& spec = input.spec();
    for (int c = 0; c < spec.nchannels; ++c) {
      std::string name = c < int(spec.channelnames.size()) ? spec.channelnames[c] : concat("channel", c);
      map.push_back({name, {sub, c}});
    }
  }
  input.seek_subimage(0, 0);
  return map;
}

bool is_8bit_format(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".gif";
}

// Reads the current subimage `sub` of `input` as float, all its channels, in
// bands of rows, handing each to use(first_row, rows, pixels). Memory stays a
// band: a whole-image read held the image in float twice more at once (this
// buffer and OpenImageIO's conversion buffer), the peak of `tempera synth`
// while it decoded its last input. Tiled files are read whole.
template <class Use>
bool read_bands(OIIO::ImageInput& input, int sub, Use&& use) {
  const OIIO::ImageSpec spec = input.spec();
  const int band_rows = spec.tile_width > 0 ? spec.height : std::min(64, spec.height);
  std::vector<float> band(std::size_t(spec.width) * spec.nchannels * std::size_t(band_rows));
  if (spec.tile_width > 0) {
    if (!input.read_image(sub, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, band.data())) return false;
    use(0, spec.height, band.data());
    return true;
  }
  for (int y = spec.y; y < spec.y + spec.height; y += band_rows) {
    const int end = std::min(y + band_rows, spec.y + spec.height);
    if (!input.read_scanlines(sub, 0, y, end, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, band.data()))
      return false;
    use(y - spec.y, end - y, band.data());
  }
  return true;
}

}  // namespace

std::int64_t max_image_pixels() { return pixel_cap().load(); }

void set_max_image_pixels(std::int64_t pixels) {
  if (pixels <= 0) throw ValueError(concat("the image size limit must be > 0 pixels, got ", pixels));
  pixel_cap() = pixels;
}

std::string temporary_name(const std::string& stem, const std::string& extension) {
  return concat(".", stem, ".tmp", getpid(), "-", random_tag(), extension);
}

ImageFileInfo inspect_image(const std::string& path) {
  auto input = open_input(path);
  ImageFileInfo info;
  info.width = input->spec().width;
  info.height = input->spec().height;
  for (auto& [name, loc] : channel_map(*input)) info.channel_names.push_back(name);
  return info;
}

Image read_image(const std::string& path, const std::vector<std::string>& channels) {
  auto input = open_input(path);
  const OIIO::ImageSpec spec0 = input->spec();
  const auto map = channel_map(*input);
  std::vector<ChannelLocation> wanted;
  std::vector<std::string> names;
  if (channels.empty()) {
    for (auto& [name, loc] : map) {
      if (loc.subimage != 0) break;  // all channels of the first part
      wanted.push_back(loc);
      names.push_back(name);
    }
  } else {
    for (const auto& name : channels) {
      auto it = std::find_if(map.begin(), map.end(), [&](auto& e) { return e.first == name; });
      if (it == map.end()) {
        std::string available;
        for (auto& e : map) available += (available.empty() ? "" : ", ") + e.first;
        throw ValueError(concat("image '", path, "' has no channel '", name, "' (it has: ", available, ")"));
      }
      wanted.push_back(it->second);
      names.push_back(name);
    }
  }
  Image out(spec0.width, spec0.height, int(wanted.size()));
  out.channel_names = names;
  // Each subimage with wanted channels is read once, band by band, and the
  // wanted channels scattered.
  for (int sub = 0; input->seek_subimage(sub, 0); ++sub) {
    const auto& spec = input->spec();
    bool needed = std::any_of(wanted.begin(), wanted.end(), [&](auto& w) { return w.subimage == sub; });
    if (!needed) continue;
    if (spec.width != spec0.width || spec.height != spec0.height)
      throw IoError(concat("image '", path, "': part ", sub, " has another size than part 0"));
    const std::size_t channels = std::size_t(spec.nchannels);
    const auto scatter = [&](int first_row, int rows, const float* band) {
      const std::size_t first = std::size_t(first_row) * spec.width, n = std::size_t(rows) * spec.width;
      for (std::size_t w = 0; w < wanted.size(); ++w) {
        if (wanted[w].subimage != sub) continue;
        const int c = wanted[w].index;
        for (std::size_t i = 0; i < n; ++i) out.data()[(first + i) * wanted.size() + w] = band[i * channels + c];
      }
    };
    if (!read_bands(*input, sub, scatter))
      throw IoError(concat("cannot read pixels of '", path, "': ", input->geterror()));
  }
  return out;
}

Image read_image_layer(const std::string& path, const std::string& layer) {
  const ImageFileInfo info = inspect_image(path);
  std::vector<std::string> selected;
  std::vector<std::string> layers;
  for (const auto& name : info.channel_names) {
    if (name == layer || name.rfind(layer + ".", 0) == 0) selected.push_back(name);
    const std::string prefix = name.substr(0, name.rfind('.'));
    if (std::find(layers.begin(), layers.end(), prefix) == layers.end()) layers.push_back(prefix);
  }
  if (selected.empty()) {
    std::string known;
    for (const auto& l : layers) known += (known.empty() ? "" : ", ") + l;
    throw ValueError(concat("image '", path, "' has no layer '", layer, "' (it has: ", known, ")"));
  }
  return read_image(path, selected);
}

namespace {

// A written file that does not read back whole (a full disk or a file size
// limit that the format's writer did not report) is never moved into place.
std::string unreadable_reason(const fs::path& file, const OIIO::ImageSpec& written) {
  auto input = OIIO::ImageInput::open(file.string());
  if (!input) {
    const std::string why = OIIO::geterror();
    return why.empty() ? "it does not read back" : why;
  }
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.width != written.width || spec.height != written.height || spec.nchannels != written.nchannels)
    return "its header does not match what was written";
  if (!read_bands(*input, 0, [](int, int, const float*) {}))
    return concat("it does not read back: ", input->geterror());
  return "";
}

}  // namespace

void write_image(const std::string& path, const ImageView& image,
                 const std::vector<std::string>& channel_names) {
  require_nonempty(image, concat("image to write to '", path, "'"));
  if (!channel_names.empty() && int(channel_names.size()) != image.channels)
    throw ValueError(concat("writing '", path, "': ", channel_names.size(), " channel names for ",
                            image.channels, " channels"));
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path() && !fs::is_directory(target.parent_path(), ec))
    throw FileNotFoundError(concat("cannot write '", path, "': folder '",
                                   target.parent_path().string(), "' does not exist"));
  // Same folder (so rename is atomic), same extension (so OIIO picks the format).
  const fs::path temp = target.parent_path() / temporary_name(target.stem().string(), target.extension().string());
  auto output = OIIO::ImageOutput::create(temp.string());
  if (!output)
    throw IoError(concat("cannot write '", path, "': no image format for extension '",
                         target.extension().string(), "'"));
  const bool eight_bit = is_8bit_format(path);
  OIIO::ImageSpec spec(image.width, image.height, image.channels,
                       eight_bit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
  if (!channel_names.empty()) spec.channelnames = channel_names;
  if (eight_bit && image.channels == 4) {
    spec.alpha_channel = 3;
    spec.attribute("oiio:UnassociatedAlpha", 1);
  }
  std::vector<float> clamped;
  const float* pixels = image.data;
  if (eight_bit) {  // OIIO would clamp too; doing it here keeps NaN out explicitly.
    clamped.resize(image.size());
    for (std::size_t i = 0; i < clamped.size(); ++i) {
      float v = image.data[i];
      clamped[i] = v != v ? 0.0f : std::clamp(v, 0.0f, 1.0f);
    }
    pixels = clamped.data();
  }
  const bool ok = output->open(temp.string(), spec) &&
                  output->write_image(OIIO::TypeDesc::FLOAT, pixels) && output->close();
  const std::string output_error = ok ? "" : output->geterror();
  output.reset();  // the file is closed before it is read back
  std::string why = ok ? unreadable_reason(temp, spec) : output_error;
  if (!why.empty()) {
    fs::remove(temp, ec);
    throw IoError(concat("cannot write '", path, "': ", why, ok ? " (is the disk full?)" : ""));
  }
  fs::rename(temp, target, ec);
  if (ec) {
    const std::string why = ec.message();  // before remove() resets ec ("...: Success")
    fs::remove(temp, ec);
    throw IoError(concat("cannot move finished image into place at '", path, "': ", why));
  }
}

Image resize_image(const ImageView& image, int width, int height) {
  require_nonempty(image, "image to resize");
  if (width <= 0 || height <= 0) throw ValueError(concat("cannot resize to ", width, "x", height));
  const OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::FLOAT);
  // OIIO only reads through this pointer; its wrapping constructor takes it non-const.
  const OIIO::ImageBuf src(spec, const_cast<float*>(image.data));
  OIIO::ImageBuf dst(OIIO::ImageSpec(width, height, image.channels, OIIO::TypeDesc::FLOAT));
  if (!OIIO::ImageBufAlgo::resize(dst, src))
    throw IoError(concat("resizing to ", width, "x", height, " failed: ", dst.geterror()));
  Image out(width, height, image.channels);
  dst.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, out.data());
  return out;
}

}  // namespace tempera

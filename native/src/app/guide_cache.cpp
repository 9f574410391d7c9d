#include "tempera/app/guide_cache.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>

#include "tempera/app/file_keys.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/app/paths.hpp"
#include "tempera/engine/error.hpp"

namespace fs = std::filesystem;

namespace tempera {
namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// The guide a channel name belongs to: "FULL.R" -> "FULL", "mask.OB_a.V" -> "mask.OB_a".
std::string guide_of_channel(const std::string& channel) {
  const std::size_t dot = channel.rfind('.');
  return dot == std::string::npos ? channel : channel.substr(0, dot);
}

}  // namespace

const Image& GuideFrame::get(const std::string& name) const {
  auto it = guides.find(name);
  if (it == guides.end()) {
    std::vector<std::string> have;
    for (const auto& [n, image] : guides) have.push_back(n);
    throw ValueError(concat("guide '", name, "' missing from '", origin, "' (it has: ", joined(have), ")"));
  }
  return it->second;
}

GuideFrame GuideFrame::read(const std::string& path, const std::vector<std::string>& names) {
  const ImageFileInfo info = inspect_image(path);
  std::vector<std::string> channels;
  std::vector<int> counts;
  for (const auto& name : names) {
    int count = 0;
    for (const auto& channel : info.channel_names)
      if (guide_of_channel(channel) == name) channels.push_back(channel), ++count;
    if (count == 0) {
      std::vector<std::string> have;
      for (const auto& channel : info.channel_names)
        if (std::find(have.begin(), have.end(), guide_of_channel(channel)) == have.end())
          have.push_back(guide_of_channel(channel));
      throw ValueError(concat("guide '", name, "' missing from '", path, "' (it has: ", joined(have), ")"));
    }
    counts.push_back(count);
  }
  GuideFrame frame;
  frame.origin = path;
  if (names.empty()) return frame;
  // One read of the file, then split: cache frames hold dozens of channels.
  const Image all = read_image(path, channels);
  int first = 0;
  for (std::size_t i = 0; i < names.size(); first += counts[i++])
    frame.guides[names[i]] = extract_channels(all.view(), first, counts[i]);
  return frame;
}

const std::vector<CacheGuide>& cache_guides() {
  static const std::vector<CacheGuide> table = {
      {"velocity_forward", {"X", "Y"}, "V+: pixel p moves to p + V+ in the next frame (pixels, x right, y down)"},
      {"velocity_backward", {"X", "Y"}, "V-: pixel p came from p - V- in the previous frame"},
      {"fluid_velocity", {"X", "Y"}, "screen velocity of fluids: p moves to p + F in the next frame"},
      {"occlusion_backward", {"V"}, "chi-: 1 visible in the previous frame, 0 disoccluded"},
      {"occlusion_forward", {"V"}, "chi+: 1 still visible in the next frame, 0 about to be occluded"},
      {"tensor", {"XX", "XY", "YY"}, "structure tensor of the grayscale render (it interpolates, angles do not)"},
      {"alpha", {"A"}, "coverage (film transparent)"},
      {"depth", {"Z"}, "Cycles' Depth pass (distance to the camera; huge on the background)"},
      {"normal", {"X", "Y", "Z"}, "world-space shading normal"},
      {"lines", {"V"}, "1 on depth and normal discontinuities"},
      {"line_distance", {"V"}, "min(distance to lines, d_max) / d_max"},
  };
  return table;
}

std::string guide_cache_frame(const std::string& folder, int frame) {
  return (fs::path(folder) / frame_file("frame_", frame, "exr")).string();
}

std::vector<int> cached_frames(const std::string& folder) {
  std::vector<int> frames;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.size() <= 10 || name.rfind("frame_", 0) != 0 || entry.path().extension() != ".exr") continue;
    const std::string digits = name.substr(6, name.size() - 10);
    if (digits.empty() || !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); }))
      continue;
    int frame = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), frame);
    // A number no frame can have (beyond Blender's last frame) is not a cache frame.
    if (ec == std::errc() && end == digits.data() + digits.size() && frame <= kMaxFrame) frames.push_back(frame);
  }
  std::sort(frames.begin(), frames.end());
  return frames;
}

int exemplar_guide_frame(const std::string& folder, std::optional<int> frame) {
  if (frame) return *frame;
  const std::vector<int> found = cached_frames(folder);
  if (found.empty())
    throw FileNotFoundError(concat("no frame_####.exr in the exemplar guide folder '", folder, "'"));
  if (found.size() > 1) {
    std::string list;
    for (int f : found) list += concat(list.empty() ? "" : ", ", f);
    throw ValueError(concat("the exemplar guide folder '", folder, "' holds ", found.size(),
                            " frames (", list, "); choose one with Exemplar Frame (--exemplar-frame)"));
  }
  return found.front();
}

}  // namespace tempera

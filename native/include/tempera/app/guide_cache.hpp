#pragma once
// The guide cache as every job reads it: one multilayer EXR per frame,
// <cache>/frame_0001.exr (docs/guide_cache.md; Python's
// tempera.app.guide_cache writes it and its manifest).
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

// Guides of one frame by name ("FULL" -> H x W x 3, "velocity_backward" -> H x W x 2, ...).
struct GuideFrame {
  std::map<std::string, Image> guides;
  std::string origin = "memory";  // the file they came from, for error messages

  // ValueError naming the guide and `origin` when it is missing.
  const Image& get(const std::string& name) const;

  // Reads the channels "<name>.<component>" of each guide from a guide cache
  // EXR in one pass. A guide absent from the file -> ValueError naming the
  // guide and the file; a missing file -> FileNotFoundError.
  static GuideFrame read(const std::string& path, const std::vector<std::string>& names);
};

// A guide of the cache besides the light paths (RGB radiance, named by
// app/light_path_guides.hpp): its name, its channel components in the order they
// are written ("<name>.<component>"), and what it holds.
struct CacheGuide {
  std::string name;
  std::vector<std::string> components;
  std::string meaning;
};

// The one table of those guides; Python's tempera.app.guide_cache.GUIDES is
// made from it and the light-path table (docs/guide_cache.md).
const std::vector<CacheGuide>& cache_guides();

// <folder>/frame_0001.exr for frame 1.
std::string guide_cache_frame(const std::string& folder, int frame);

// The frame numbers of the frame_####.exr files in `folder`, sorted.
std::vector<int> cached_frames(const std::string& folder);

// The exemplar's guide cache frame: `frame` if given, else the folder's only
// frame_*.exr (FileNotFoundError if none, ValueError if several).
int exemplar_guide_frame(const std::string& folder, std::optional<int> frame);

}  // namespace tempera

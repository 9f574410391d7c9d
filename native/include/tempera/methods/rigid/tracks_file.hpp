#pragma once
// tracks.json, the rigid-body method's input in a guide cache (and in each
// exemplar folder): every object's track and collision events, as
// tempera.methods.rigid.rigid_tracks writes them (docs/rigid_bodies.md), and the
// frame size from the cache's manifest.json. User input: every value is
// checked, and a bad one is named with the file and the object.
#include <map>
#include <string>

#include "tempera/methods/rigid/rigid.hpp"

namespace tempera {

constexpr const char* kTracksName = "tracks.json";
constexpr int kTracksFormat = 1;

struct TracksFile {
  int frame_start = 1;
  Vec2 gravity{0, 1};  // px per frame^2
  std::map<std::string, Track> objects;
  // Each object's distance along the view axis per frame ("depth", which the
  // Blender side writes): the order in which objects are laid over each other.
  std::map<std::string, std::vector<double>> depths;
  int frame_count() const { return objects.empty() ? 0 : int(objects.begin()->second.frames.size()); }
};

// The tracks of `folder`/tracks.json. FileNotFoundError when there is none,
// ValueError naming the file (and the object) for malformed text or values.
TracksFile read_tracks_file(const std::string& folder);

// Writes `folder`/tracks.json atomically (a temporary file, then a rename).
void write_tracks_file(const std::string& folder, const TracksFile& tracks);

// (width, height) of a guide cache's frames, from its manifest.json;
// ValueError naming the file when it is missing, malformed or over the
// image size limit.
std::pair<int, int> guide_cache_frame_size(const std::string& cache);

}  // namespace tempera

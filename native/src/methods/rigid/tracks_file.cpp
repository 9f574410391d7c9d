#include "tempera/methods/rigid/tracks_file.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tempera/app/image_io.hpp"
#include "tempera/app/json.hpp"
#include "tempera/app/paths.hpp"
#include "tempera/app/text_file.hpp"
#include "tempera/engine/error.hpp"

namespace fs = std::filesystem;

namespace tempera {
namespace {

bool is_number(const Json* v) { return v && v->type == Json::Type::Number; }

double number(const Json& v, const char* what) {
  if (v.type != Json::Type::Number) throw ValueError(concat(what, " must be a number"));
  return v.number;
}

Vec2 vec2(const Json& v, const char* what) {
  if (v.type != Json::Type::Array || v.items.size() != 2) throw ValueError(concat(what, " must have 2 numbers"));
  return {number(v.items[0], what), number(v.items[1], what)};
}

const Json& list(const Json& track, const char* key) {
  const Json* v = track.find(key);
  if (!v) throw ValueError(concat("a track needs '", key, "'"));
  if (v->type != Json::Type::Array) throw ValueError(concat("a track's '", key, "' must be a list"));
  return *v;
}

Track track_of(const Json& d) {
  if (d.type != Json::Type::Object) throw ValueError("not a track");
  const Json &centre = list(d, "centre"), &velocity = list(d, "velocity"), &theta = list(d, "theta"),
             &radius = list(d, "radius");
  const std::size_t n = centre.items.size();
  if (velocity.items.size() != n || theta.items.size() != n || radius.items.size() != n)
    throw ValueError("a track's centre, velocity, theta and radius need one entry per frame");
  Track t;
  for (std::size_t f = 0; f < n; ++f)
    t.frames.push_back({vec2(centre.items[f], "a centre"), vec2(velocity.items[f], "a velocity"),
                        number(theta.items[f], "a theta"), number(radius.items[f], "a radius")});
  if (const Json* events = d.find("events")) {
    if (events->type != Json::Type::Array) throw ValueError("a track's 'events' must be a list");
    for (const Json& e : events->items) {
      const Json* frame = e.find("frame");
      if (!is_number(frame) || !frame->integer) throw ValueError("an event needs a whole frame number");
      const Json *contact = e.find("contact"), *normal = e.find("normal");
      if (!contact || !normal) throw ValueError("an event needs a contact and a normal");
      if (std::abs(frame->number) > 1e9) throw ValueError(concat("event frame ", frame->number, " is outside the track"));
      t.events.push_back({int(frame->number), vec2(*contact, "a contact"), vec2(*normal, "a normal")});
    }
  }
  validate_track(t);
  derive_trajectory_angles(t);
  return t;
}

std::vector<double> depths_of(const Json& depth, const Track& track) {
  if (depth.type != Json::Type::Array || depth.items.size() != track.frames.size())
    throw ValueError("a track's 'depth' needs one number per frame");
  std::vector<double> out;
  for (const Json& d : depth.items) {
    out.push_back(number(d, "a depth"));
    if (!std::isfinite(out.back())) throw ValueError(concat("depth ", out.back(), " at frame ", out.size() - 1, " is not finite"));
  }
  return out;
}

Json json_of(const Vec2& v) { return Json::array({Json::of(v.x), Json::of(v.y)}); }

// The track as tempera.methods.rigid.rigid_tracks writes one.
Json json_of(const Track& t) {
  std::vector<Json> centre, velocity, theta, radius, delta, alpha, events;
  for (const TrackFrame& f : t.frames) {
    centre.push_back(json_of(f.centre)), velocity.push_back(json_of(f.velocity));
    theta.push_back(Json::of(f.theta)), radius.push_back(Json::of(f.radius));
    delta.push_back(Json::of(f.delta)), alpha.push_back(Json::of(f.alpha));
  }
  for (const RigidEvent& e : t.events)
    events.push_back(Json::object({{"frame", Json::of(double(e.frame))}, {"contact", json_of(e.contact)},
                                   {"normal", json_of(e.normal)}, {"obstacle", Json::of(std::string("static"))}}));
  return Json::object({{"centre", Json::array(centre)}, {"velocity", Json::array(velocity)},
                       {"theta", Json::array(theta)}, {"radius", Json::array(radius)}, {"delta", Json::array(delta)},
                       {"alpha", Json::array(alpha)}, {"events", Json::array(events)}});
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(concat("cannot read '", path.string(), "'"));
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

Json parse_file(const fs::path& path, const char* what) {
  try {
    return parse_json(read_text(path));
  } catch (const ValueError& e) {
    throw ValueError(concat(path.string(), ": unreadable ", what, " (", e.what(), ")"));
  }
}

}  // namespace

TracksFile read_tracks_file(const std::string& folder) {
  const fs::path path = fs::path(folder) / kTracksName;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw FileNotFoundError(concat(path.string(), ": no rigid-body tracks in this guide cache (render the guides of a "
                                   "baked rigid-body world first)"));
  const Json data = parse_file(path, "tracks");
  const Json *format = data.find("format"), *objects = data.find("objects");
  if (!is_number(format) || format->number != kTracksFormat || !objects || objects->type != Json::Type::Object)
    throw ValueError(concat(path.string(), ": not a tracks file of format ", kTracksFormat));
  TracksFile tracks;
  const Json* start = data.find("frame_start");
  if (!is_number(start) || !start->integer || start->number < 0 || start->number > kMaxFrame)
    throw ValueError(concat(path.string(), ": frame_start must be a whole number from 0 to ", kMaxFrame));
  tracks.frame_start = int(start->number);
  const Json* gravity = data.find("gravity");
  if (!gravity || gravity->type != Json::Type::Array || gravity->items.size() != 2 || !is_number(&gravity->items[0]) ||
      !is_number(&gravity->items[1]) || !std::isfinite(gravity->items[0].number) ||
      !std::isfinite(gravity->items[1].number))
    throw ValueError(concat(path.string(), ": gravity must be 2 finite numbers"));
  tracks.gravity = {gravity->items[0].number, gravity->items[1].number};
  for (const auto& [name, track] : objects->fields) {
    try {
      tracks.objects[name] = track_of(track);
      if (const Json* depth = track.find("depth")) tracks.depths[name] = depths_of(*depth, tracks.objects[name]);
    } catch (const ValueError& e) {
      throw ValueError(concat(path.string(), ": object '", name, "': ", e.what()));
    }
  }
  return tracks;
}

void write_tracks_file(const std::string& folder, const TracksFile& tracks) {
  std::vector<std::pair<std::string, Json>> objects;
  for (const auto& [name, track] : tracks.objects) {
    objects.emplace_back(name, json_of(track));
    if (const auto depth = tracks.depths.find(name); depth != tracks.depths.end()) {
      std::vector<Json> values;
      for (double d : depth->second) values.push_back(Json::of(d));
      objects.back().second.fields.emplace_back("depth", Json::array(values));
    }
  }
  const Json data = Json::object({{"format", Json::of(double(kTracksFormat))},
                                  {"frame_start", Json::of(double(tracks.frame_start))},
                                  {"gravity", json_of(tracks.gravity)},
                                  {"objects", Json::object(std::move(objects))}});
  const fs::path path = fs::path(folder) / kTracksName;
  const std::string text = write_json(data);
  std::error_code ec;
  // The same tracks again leave the file as it is, so that the frames made
  // from it stay current (their records stamp its time).
  if (fs::is_regular_file(path, ec) && read_text(path) == text) return;
  create_output_folder(folder);
  write_text_atomically(path.string(), text, "the tracks");
}

std::pair<int, int> guide_cache_frame_size(const std::string& cache) {
  const fs::path path = fs::path(cache) / "manifest.json";
  const Json* resolution = nullptr;
  Json manifest;
  try {
    manifest = parse_json(read_text(path));
    resolution = manifest.find("resolution");
  } catch (const std::exception&) {
  }
  if (!resolution) throw ValueError(concat(cache, ": no manifest.json with the frames' resolution"));
  const auto whole = [](const Json& v) { return v.type == Json::Type::Number && v.integer && v.number >= 1; };
  if (resolution->type != Json::Type::Array || resolution->items.size() != 2 || !whole(resolution->items[0]) ||
      !whole(resolution->items[1]))
    throw ValueError(concat(path.string(), ": the resolution must be 2 whole numbers >= 1"));
  const double width = resolution->items[0].number, height = resolution->items[1].number;
  if (width * height > double(max_image_pixels()))
    throw ValueError(concat(path.string(), ": the resolution ", std::int64_t(width), "x", std::int64_t(height), " is more than the limit of ",
                            max_image_pixels(), " pixels (raise it with TEMPERA_MAX_IMAGE_PIXELS if real)"));
  return {int(width), int(height)};
}

}  // namespace tempera

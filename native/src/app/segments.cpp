#include "tempera/app/segments.hpp"

#include <algorithm>
#include <string>

#include "tempera/engine/error.hpp"

namespace tempera {

std::vector<Segment> key_segments(const std::vector<int>& frames, const std::vector<int>& key_frames) {
  if (frames.empty()) throw ValueError("a shot needs at least one frame to cut into segments");
  std::vector<int> bounds = {frames.front()};
  for (int k : key_frames)
    if (k > frames.front() && k < frames.back()) bounds.push_back(k);
  if (frames.back() != frames.front()) bounds.push_back(frames.back());
  std::sort(bounds.begin(), bounds.end());
  bounds.erase(std::unique(bounds.begin(), bounds.end()), bounds.end());
  if (bounds.size() == 1) return {Segment{bounds[0], bounds[0], {bounds[0]}}};
  std::vector<Segment> out;
  for (std::size_t i = 0; i + 1 < bounds.size(); ++i) {
    Segment s{bounds[i], bounds[i + 1], {}};
    const int end = i + 2 == bounds.size() ? s.last : s.last - 1;
    for (int f = s.first; f <= end; ++f) s.writes.push_back(f);
    out.push_back(s);
  }
  return out;
}

std::vector<std::size_t> select_segments(const std::vector<Segment>& segments,
                                         const std::optional<std::pair<int, int>>& only) {
  std::vector<std::size_t> out;
  std::string list;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    if (!only || (segments[i].first == only->first && segments[i].last == only->second)) out.push_back(i);
    list += concat(i ? ", " : "", segments[i].first, "-", segments[i].last);
  }
  if (out.empty())
    throw ValueError(concat("segment ", only->first, "-", only->second, " is not one of the shot's segments (",
                            list, "; they run from key to key)"));
  return out;
}

}  // namespace tempera

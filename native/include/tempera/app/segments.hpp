#pragma once
// The segment unit of work (the job core's third, after the independent and
// the chained frame): a shot cut at its key frames into pieces solved
// together, each independent of the others (painted keys bound the solve
// on both sides: app/segment_job.hpp). One rule, used by the segment
// method's job, its Python wrapper and the farm planner (through the
// binding); farm/flamenco/tempera.js holds the one copy that cannot call it,
// tested against it.
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

namespace tempera {

// Frames first..last (inclusive) are solved together; the segment writes
// `writes` (first..last - 1, and last too for the shot's last segment), so a
// key shared by two segments has one writer.
struct Segment {
  int first = 0, last = 0;
  std::vector<int> writes;
};

// The segments of a shot of consecutive, sorted `frames`: from its first frame
// to each key inside it, key to key, and on to its last frame; a one-frame
// shot is one segment. Keys at or outside the shot's ends add no bound.
std::vector<Segment> key_segments(const std::vector<int>& frames, const std::vector<int>& key_frames);

// The indices of the segments to run: all, or the one from only->first to
// only->second (a farm task); ValueError listing the shot's segments when it is not one.
std::vector<std::size_t> select_segments(const std::vector<Segment>& segments,
                                         const std::optional<std::pair<int, int>>& only);

}  // namespace tempera

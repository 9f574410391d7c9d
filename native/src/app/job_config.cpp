#include "tempera/app/job_config.hpp"

#include <algorithm>

#include "tempera/app/paths.hpp"
#include "tempera/engine/error.hpp"

namespace tempera {

void check_job_config(const JobConfig& c, FrameOrder order, const std::string& why) {
  if (c.frames.empty()) throw ValueError("no frames to make (give a frame range)");
  for (int frame : c.frames)
    if (frame < 0 || frame > kMaxFrame)
      throw ValueError(concat("frame numbers must be from 0 to ", kMaxFrame, " (Blender's last frame), got ", frame));
  if (order == FrameOrder::Consecutive) {
    for (std::size_t i = 1; i < c.frames.size(); ++i)
      if (c.frames[i] != c.frames[i - 1] + 1)
        throw ValueError(concat(why, "; frame ", c.frames[i - 1], " is followed by ", c.frames[i]));
  } else {
    std::vector<int> sorted = c.frames;  // n log n: a million frames are checked at once
    std::sort(sorted.begin(), sorted.end());
    const auto twice = std::adjacent_find(sorted.begin(), sorted.end());
    if (twice != sorted.end()) throw ValueError(concat("frame ", *twice, " is listed twice"));
  }
  if (c.format != "png" && c.format != "exr")
    throw ValueError(concat("unknown output format '", c.format, "' (choose png or exr)"));
  if (c.out.empty()) throw ValueError("no output folder given");
}

}  // namespace tempera

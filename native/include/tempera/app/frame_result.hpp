#pragma once
// The one result of a job's unit of work for one frame, whatever the method.
#include <limits>
#include <string>

namespace tempera {

struct FrameResult {
  int frame = 0;
  std::string path;       // the output file
  std::string status;     // "stylized" (the noise pass: "made") | "skipped" (already current)
  double seconds = 0;
  // Flicker against the previous frame along the motion (light-path guided
  // frames); NaN where it is not measured (no previous frame, no motion guides).
  double flicker = std::numeric_limits<double>::quiet_NaN();
  double source_coverage = 0;  // fraction of exemplar patches used, where the method reports it
};

}  // namespace tempera

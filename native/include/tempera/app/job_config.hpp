#pragma once
// What every job's config has. A method's config derives from it and adds
// its own, so the command line, the bindings and the job core read these
// fields one way.
#include <string>
#include <vector>

namespace tempera {

struct JobConfig {
  // The look: a painting, a medium, an RGBA image or a folder of frames (a
  // video exemplar), as the method takes it.
  std::string exemplar;
  std::string guides;          // the shot's guide cache folder (the noise pass: optional)
  std::vector<int> frames;     // the frames to make, in this order
  std::string out;             // output folder
  std::string format = "png";  // png | exr
  bool resume = true;          // skip what is current; false: make everything again
};

// What a method's unit of work asks of the frame list: chained frames and
// segments need consecutive frames.
enum class FrameOrder { Any, Consecutive };

// ValueError naming the problem: no frames, a frame outside 0 to kMaxFrame,
// a frame listed twice, an unknown format, no output folder; with
// Consecutive also a gap, after `why` ("... needs consecutive frames (each is
// advected from the one before)").
void check_job_config(const JobConfig& config, FrameOrder order = FrameOrder::Any, const std::string& why = "");

}  // namespace tempera

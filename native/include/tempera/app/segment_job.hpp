#pragma once
// A job whose unit of work is the segment (app/segments.hpp): a shot cut at
// its key frames into pieces, each solved whole and independent of the
// others. The command line's one loop (cli/frame_loop.hpp, run_units) drives
// it a segment at a time as it drives a FrameJob a frame at a time, so that
// progress, cancel and resume look alike.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "tempera/app/frame_result.hpp"
#include "tempera/app/job_inputs.hpp"
#include "tempera/app/segments.hpp"

namespace tempera {

// Where a segment's solve is: the fraction done, and the stage just
// finished ("level 2/4 forward sweep"; empty between stages). Returning
// false cancels.
using StageProgress = std::function<bool(double fraction, const std::string& finished)>;

class SegmentJob {
 public:
  virtual ~SegmentJob() = default;
  virtual const std::vector<Segment>& segments() const = 0;
  // The indices of the segments to run: all, or a farm task's one.
  virtual const std::vector<std::size_t>& selected() const = 0;
  // True unless the job runs one segment of the shot (a farm task): only a
  // run over the whole shot writes what goes beside the frames.
  virtual bool whole_shot() const = 0;
  // Solves segments()[index] (or skips it when current) and writes its
  // frames; the result's frame is the segment's first. Cancelling:
  // CancelledError, nothing of the segment written.
  virtual FrameResult run_unit(std::size_t index, const StageProgress& progress = {}) = 0;
  // Every file and folder the job reads (app/frame_job.hpp).
  virtual const JobInputs& inputs() const = 0;
  virtual const std::vector<std::string>& warnings() const = 0;
  // The exemplar followed by the frames written so far.
  virtual void write_contact_sheet(const std::string& path, int columns = 0) const = 0;
};

}  // namespace tempera

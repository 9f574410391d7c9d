#pragma once
// A job whose unit of work is one frame (independent or chained): every
// method's per-frame job and the noise pass derive from it. The command
// line's frame loop (and, through their bindings, the panel's modal
// operators) drive every one of them the same way, a frame at a time, so that
// progress, cancel and resume look alike.
#include <cstddef>
#include <string>
#include <vector>

#include "tempera/app/frame_result.hpp"
#include "tempera/app/job_inputs.hpp"
#include "tempera/engine/synthesis.hpp"  // ProgressCallback

namespace tempera {

class FrameJob {
 public:
  virtual ~FrameJob() = default;
  // The frames to make, in order.
  virtual const std::vector<int>& frames() const = 0;
  virtual std::string output_path(int frame) const = 0;
  // Makes frames()[index], or skips it when its output is current.
  // `progress` returning false cancels: CancelledError, nothing of the frame written.
  virtual FrameResult run_frame(std::size_t index, const ProgressCallback& progress = {}) = 0;
  // Every file and folder the job reads: whatever else a front end writes
  // (a contact sheet, a video) is checked against them too.
  virtual const JobInputs& inputs() const = 0;
  // What was fixed on the way (a resampled painting, a damaged record set aside); none by default.
  virtual const std::vector<std::string>& warnings() const;
  // The picture a front end writes beside the frames when a run ends: the
  // exemplar followed by the frames written so far. A method without one
  // says false, and its write_contact_sheet throws std::logic_error.
  virtual bool has_contact_sheet() const { return false; }
  virtual void write_contact_sheet(const std::string& path, int columns = 0) const;
  // How the run went, in a phrase for the command's last line ("flow from
  // velocity_forward"); empty by default.
  virtual std::string summary() const { return ""; }
};

// The unit "chained frame": a frame that continues the one before (the
// previous frame's state advected, or its matches as the start). The core makes a frame's missing predecessors first, in
// order, so that any frame may be asked for (the panel's "this frame", a
// script, a resumed run) and the result equals an uninterrupted run's.
class ChainedFrameJob : public FrameJob {
 public:
  // Skips frames()[index] when current; else makes the frames before it that
  // are neither current nor made by this job, then it. Cancelling in any of
  // them cancels the call (CancelledError); the frames finished stay.
  FrameResult run_frame(std::size_t index, const ProgressCallback& progress = {}) final;

 protected:
  // The frame's output and record are current on disk (and resume is on).
  virtual bool is_current(std::size_t index) const = 0;
  // Makes frames()[index], whose predecessor is current or was just made.
  virtual FrameResult make_frame(std::size_t index, const ProgressCallback& progress) = 0;

 private:
  std::vector<bool> made_;  // per index: made by this job, so usable whatever resume says
};

}  // namespace tempera

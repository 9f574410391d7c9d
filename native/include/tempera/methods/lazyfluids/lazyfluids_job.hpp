#pragma once
// LazyFluids (lazyfluids.hpp) as a job of chained frames over a guide cache: `tempera stylize
// --method lazyfluids` and the Python FluidJob. The target alpha of frame f
// is the cache's `alpha`, its flow `fluid_velocity` (falling back to
// `velocity_forward`, else zero, with a warning). The exemplar is an RGBA
// image or a folder of RGBA frames (a video exemplar, looped). Frames run
// forwards and each depends on the one before, so the unit of resume is the
// frame: its output and its exact float state (OUT/tempera_lazyfluids/
// frame_0001.exr, what the next frame advects) are written atomically, then a
// record with the frame's key (settings, exemplar, guide files, the previous
// state's checksum) and the files' checksums; a rerun skips frames whose
// record still matches, and a resumed run equals an uninterrupted one.
#include <string>
#include <vector>

#include "tempera/methods/lazyfluids/lazyfluids.hpp"
#include "tempera/app/frame_job.hpp"
#include "tempera/app/job_config.hpp"

namespace tempera {

// exemplar: an RGBA image, or a folder of RGBA frames (sorted by name);
// guides: the guide cache (frame_####.exr); frames: consecutive; out: the
// output folder, OUT/frame_0001.png ...
struct LazyFluidsJobConfig : JobConfig {
  LazyFluidsOptions options = default_lazyfluids_options();
};

class LazyFluidsJob : public ChainedFrameJob {
 public:
  // Validates everything up front (files, guides, sizes, options).
  explicit LazyFluidsJob(LazyFluidsJobConfig config);

  const std::vector<int>& frames() const override { return config_.frames; }
  const std::vector<std::string>& warnings() const override { return warnings_; }
  const JobInputs& inputs() const override { return inputs_; }
  const std::vector<Image>& exemplar() const { return exemplar_; }
  std::string output_path(int frame) const override;
  std::string state_path(int frame) const;
  std::string record_path(int frame) const;
  std::string field_path(int frame) const;  // warm start: the frame's final matches

  // The exemplar followed by the frames written so far.
  bool has_contact_sheet() const override { return true; }
  void write_contact_sheet(const std::string& path, int columns = 0) const override;

 private:
  std::string guide_path(int frame) const;
  std::string frame_key(std::size_t index) const;
  bool is_current(std::size_t index) const override;
  // Stylizes frames()[index] from the previous frame's state. `progress`
  // returning false cancels: CancelledError, nothing written.
  FrameResult make_frame(std::size_t index, const ProgressCallback& progress) override;
  Image read_flow(int frame) const;
  void write_frame(std::size_t index, const FluidFrameResult& frame) const;

  LazyFluidsJobConfig config_;
  std::vector<std::string> warnings_, exemplar_files_;
  JobInputs inputs_;
  std::vector<Image> exemplar_;
  std::vector<std::string> flow_guide_;  // per frame index: the guide read as flow ("" = zero)
  std::string settings_;
};

}  // namespace tempera

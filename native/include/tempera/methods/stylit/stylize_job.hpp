#pragma once
// A stylization job over an animation: the painting, the exemplar's guide
// cache frame and the target guide cache in, one stylized image per frame
// out. Shared by `tempera stylize` and the Blender add-on, which calls
// run_frame() once per modal step. Frames are resumable: each output is
// written atomically and recorded with a key in the job core's shared frame
// report OUT/tempera_stylize.json (app/frame_report.hpp: farm tasks share the
// folder), and a rerun skips frames whose key still matches.
#include <optional>
#include <string>
#include <vector>

#include "tempera/app/frame_job.hpp"
#include "tempera/app/frame_report.hpp"
#include "tempera/app/guide_cache.hpp"
#include "tempera/app/light_path_shot.hpp"
#include "tempera/app/job_config.hpp"
#include "tempera/engine/image.hpp"
#include "tempera/methods/stylit/stylit.hpp"

namespace tempera {

// The painting, the exemplar's and the animation's guide caches, frames and
// output folder (app/light_path_shot.hpp), and StyLit's options.
struct StylizeJobConfig : LightPathShotConfig {
  StylitOptions stylit;
};

class StylizeJob : public FrameJob {
 public:
  // Validates everything up front (files, guides, sizes); see docs/cli.md.
  explicit StylizeJob(StylizeJobConfig config);

  const std::vector<int>& frames() const override { return config_.frames; }
  // What was fixed on the way: a resampled painting, a damaged resume record set aside.
  const std::vector<std::string>& warnings() const override { return warnings_; }
  const JobInputs& inputs() const override { return shot_.inputs(); }
  std::string output_path(int frame) const override { return shot_.output_path(frame); }
  std::string report_path() const;
  // With warm_start: the frame's final matches (source positions), read by the next frame.
  std::string field_path(int frame) const;
  // The painting, the exemplar's guides and the shot's frames, as read and checked.
  const LightPathShot& shot() const { return shot_; }

  // Stylizes frames()[index] (or skips it when its output is current).
  // `progress` returning false cancels: CancelledError, nothing written.
  FrameResult run_frame(std::size_t index, const ProgressCallback& progress = {}) override;

  bool has_contact_sheet() const override { return true; }
  void write_contact_sheet(const std::string& path, int columns = 0) const override {
    shot_.write_contact_sheet(path, columns);
  }

 private:
  bool has_temporal_predecessor(std::size_t index) const;
  std::string field_folder() const;  // OUT/tempera_stylize
  void check_temporal_guides() const;

  StylizeJobConfig config_;
  FrameReport report_;  // the resume record, shared with other processes writing this folder
  std::vector<std::string> warnings_;
  LightPathShot shot_;
  std::string settings_;           // canonical text of the stylization settings
  std::vector<std::string> keys_;  // resume key per frame index
};

}  // namespace tempera

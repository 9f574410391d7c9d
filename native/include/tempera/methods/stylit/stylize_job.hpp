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
#include "tempera/app/job_config.hpp"
#include "tempera/engine/image.hpp"
#include "tempera/methods/stylit/stylit.hpp"

namespace tempera {

// exemplar: the painting (PNG, EXR, ...); guides: the animation's guide
// cache; out: the output folder (created).
struct StylizeJobConfig : JobConfig {
  std::string exemplar_guides;        // guide cache folder of the exemplar render
  std::optional<int> exemplar_frame;  // default: the folder's only frame_*.exr
  std::string prefix = "frame_";      // OUT/<prefix>0001.<format>
  StylitOptions stylit;
};

class StylizeJob : public FrameJob {
 public:
  // Validates everything up front (files, guides, sizes); see docs/cli.md.
  explicit StylizeJob(StylizeJobConfig config);

  const std::vector<int>& frames() const override { return config_.frames; }
  // What was fixed on the way: a resampled painting, a damaged resume record set aside.
  const std::vector<std::string>& warnings() const override { return warnings_; }
  const JobInputs& inputs() const override { return inputs_; }
  std::string output_path(int frame) const override;
  std::string report_path() const;
  // The painting at the exemplar guides' size, the exemplar's guides and their
  // file: what the coherent job (tcia_job.hpp) takes from this one.
  const Image& style() const { return style_; }
  const GuideFrame& exemplar() const { return exemplar_; }
  const std::string& exemplar_path() const { return exemplar_path_; }
  std::string target_guides_path(int frame) const { return target_path(frame); }

  // Stylizes frames()[index] (or skips it when its output is current).
  // `progress` returning false cancels: CancelledError, nothing written.
  FrameResult run_frame(std::size_t index, const ProgressCallback& progress = {}) override;

  // The painting followed by the stylized frames written so far, downscaled
  // so that the sheet stays within about 2000 pixels wide. columns 0 = auto.
  bool has_contact_sheet() const override { return true; }
  void write_contact_sheet(const std::string& path, int columns = 0) const override;

 private:
  std::string target_path(int frame) const;
  bool has_temporal_predecessor(std::size_t index) const;
  void check_target_guides(const std::vector<std::string>& names);

  StylizeJobConfig config_;
  FrameReport report_;  // the resume record, shared with other processes writing this folder
  std::vector<std::string> warnings_;
  JobInputs inputs_;
  Image style_;  // the painting at the exemplar guides' size
  GuideFrame exemplar_;
  std::string exemplar_path_;
  std::string settings_;           // canonical text of the stylization settings
  std::vector<std::string> keys_;  // resume key per frame index
  std::vector<bool> has_motion_;   // target frame has velocity_backward and occlusion_backward
};

}  // namespace tempera

#pragma once
// Color Me Noisy over a sequence: a folder of coherent frames R (Tempera's
// own coherent result, or frames from elsewhere), or the render of a guide
// cache (the paper's 3D case: a render whose materials look like the
// medium), in, one noisy frame each out. Shared by `tempera noisy`, `tempera stylize --noise` and the Blender
// add-on, which calls run_frame() once per modal step. Frames are
// independent, so a farm may split the range anywhere; each output is
// written atomically with a key beside it (OUT/.tempera_noisy/0001.key), and
// a rerun skips frames whose key still matches.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tempera/app/frame_job.hpp"
#include "tempera/app/job_config.hpp"
#include "tempera/engine/image.hpp"
#include "tempera/methods/noisy/noisy.hpp"
#include "tempera/app/light_path_guides.hpp"

namespace tempera {

// exemplar: the medium S (the painting, or a scan of the paper; empty when R
// is the render: its first frame under a paper grain, render_medium.hpp); out: the
// output folder (created), <prefix>0001.png ...; format: png only; guides:
// the guide cache, for a guide noise map and guided noise.
struct NoisySequenceConfig : JobConfig {
  // Folder of the coherent frames R: <prefix>0001.png ...; empty: the render,
  // the guide cache's FULL guide (Cycles' Combined pass) in display sRGB.
  std::string reference;
  std::string prefix = "frame_";  // of the reference and the output frames
  // Optional local noise map (§3.3), f_p = noise * map: an image file (R's
  // size), or the name of a guide in the guide cache `guides` ("alpha",
  // "mask.OB_Cube", an AOV), read per frame. 0 keeps R, 1 is the full amount.
  std::string noise_map;
  // Guided noise (options.noise_guides > 0): the exemplar render's guide
  // cache (its only frame, or exemplar_frame) and the light-path guides'
  // weights (app/light_path_guides.hpp).
  std::string exemplar_guides;
  std::optional<int> exemplar_frame;
  GuideWeights guide_weights = default_guide_weights();
  NoisyOptions options = default_noisy_options();
};

class NoisySequence : public FrameJob {
 public:
  // Validates up front: options, folders, the exemplar, every reference
  // frame, the noise map (file or guide); ValueError / FileNotFoundError.
  explicit NoisySequence(NoisySequenceConfig config);
  const std::vector<int>& frames() const override { return config_.frames; }
  const JobInputs& inputs() const override { return inputs_; }
  std::string output_path(int frame) const override;
  // Makes frames()[index] (or skips it when its output is current).
  // `progress` returning false cancels: CancelledError, nothing written.
  FrameResult run_frame(std::size_t index, const ProgressCallback& progress = {}) override;
  // The medium followed by the frames written so far.
  bool has_contact_sheet() const override { return true; }
  void write_contact_sheet(const std::string& path, int columns = 0) const override;

 private:
  void refuse_writing_on_inputs();
  bool renders() const { return config_.reference.empty(); }  // R is the guide cache's render
  std::string reference_path(int frame) const;  // its file (the guide frame when it renders)
  Image reference_frame(int frame) const;
  std::string guide_path(int frame) const;
  bool map_is_guide() const { return !config_.noise_map.empty() && !map_file_; }
  Image noise_map(int frame) const;
  bool guided() const { return config_.options.noise_guides > 0; }
  void read_exemplar_guides();
  std::vector<Image> frame_guides(int frame) const;  // tone-mapped, in light_path_ order
  std::string key(int frame) const;

  NoisySequenceConfig config_;
  JobInputs inputs_;
  Image medium_;
  bool map_file_ = false;
  Image file_map_;
  std::string settings_;
  std::vector<std::pair<std::string, float>> light_path_;  // guided noise: the active guides
  std::vector<Image> exemplar_guides_;                      // their exemplar side, tone-mapped
};

}  // namespace tempera

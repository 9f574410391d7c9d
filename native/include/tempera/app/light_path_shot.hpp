#pragma once
// What the methods that match a painting of an exemplar render to a shot by
// its light-path guides read and write (StyLit per frame, the coherent
// method): the painting at the exemplar guides' size, the exemplar render's
// guides, the shot's guide cache with every frame's light-path guides
// checked, the names of the frames written and their contact sheet. Each
// method's job holds one and adds its own solve, keys and records.
#include <optional>
#include <string>
#include <vector>

#include "tempera/app/guide_cache.hpp"
#include "tempera/app/job_config.hpp"
#include "tempera/app/job_inputs.hpp"
#include "tempera/engine/image.hpp"

namespace tempera {

// exemplar: the painting (PNG, EXR, ...); guides: the shot's guide cache;
// out: the output folder, OUT/<prefix>0001.<format> ...
struct LightPathShotConfig : JobConfig {
  std::string exemplar_guides;        // guide cache folder of the exemplar render
  std::optional<int> exemplar_frame;  // default: the folder's only frame_*.exr
  std::string prefix = "frame_";
};

class LightPathShot {
 public:
  // Reads the painting and the exemplar's `guides` (light-path guide names)
  // and checks every frame of the shot for them, in this order, with
  // FileNotFoundError or ValueError naming the file; then refuses an output
  // folder or frame that is one of those inputs. A painting of the exemplar's
  // aspect but another size is resampled, with a warning in `warnings`.
  LightPathShot(const LightPathShotConfig& config, const std::vector<std::string>& guides,
                std::vector<std::string>& warnings);

  // Creates the output folder and removes temporary files that writers killed
  // long ago left there: call once every output is known to be no input.
  void prepare_output() const;

  const Image& style() const { return style_; }  // the painting at the exemplar guides' size
  const GuideFrame& exemplar() const { return exemplar_; }
  const std::string& exemplar_path() const { return exemplar_path_; }
  const std::vector<std::string>& guides() const { return guides_; }  // the light-path guides read, in order
  std::string target_path(int frame) const;  // the shot's guide cache frame
  std::string output_path(int frame) const;
  // frames[index] has velocity_backward and occlusion_backward.
  bool has_motion(std::size_t index) const { return has_motion_.at(index); }
  const JobInputs& inputs() const { return inputs_; }

  // The painting followed by the frames written so far, downscaled so that
  // the sheet stays within about 2000 pixels wide. columns 0 = auto.
  void write_contact_sheet(const std::string& path, int columns = 0) const;

 private:
  LightPathShotConfig config_;
  std::vector<std::string> guides_;
  JobInputs inputs_;
  Image style_;
  GuideFrame exemplar_;
  std::string exemplar_path_;
  std::vector<bool> has_motion_;
};

}  // namespace tempera

#pragma once
// Fluidymation (fluidymation.hpp) as a job over a guide cache: `tempera
// stylize --method fluidymation` and the Blender panel's "Natural media".
// The target is a mask per frame (the cache's `alpha`, or a `mask.OB_*` /
// `mask.CO_*` guide) with its flow (the cache's exact velocity_forward, or
// made from the masks); the exemplar is a folder of frames (RGBA: the alpha
// is its mask; RGB: masks from a second folder), whose flow is always made
// from its masks (App. A). All of the target's masks are read up front:
// ext- runs backward from the last frame.
//
// Frames are solved in order, each from the previous frame's matches. Each
// frame writes, atomically and in this order, its image (RGBA, alpha = the
// target mask), its matches (OUT/tempera_fluidymation/nnf_NNNN.exr) and a
// record with its key (settings, every input file, and the previous frame's
// key, so a frame is current only if everything before it is too). A rerun
// skips current frames and resumes from the last current frame's matches, so
// resumed == uninterrupted. With `bidirectional` the whole shot is solved on
// the first frame that needs it (the backward pass starts at the last frame).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tempera/app/frame_job.hpp"
#include "tempera/app/job_config.hpp"
#include "tempera/methods/fluidymation/fluidymation.hpp"

namespace tempera {

// Where the target's flow comes from: fluid = the cache's fluid_velocity
// (Mantaflow smoke and liquids, whose Vector pass is zero), guides = its
// velocity_forward, masks = made from the target masks (App. A).
enum class FlowSource { Auto, Fluid, Guides, Masks };
template <>
struct EnumNames<FlowSource> {
  static constexpr const char* what = "flow source";
  static constexpr std::array<const char*, 4> names = {"auto", "fluid", "guides", "masks"};
};

// exemplar: a folder of exemplar frames (PNG, EXR, ...), in name order;
// guides: the guide cache; frames: consecutive.
struct FluidymationJobConfig : JobConfig {
  std::string exemplar_masks;  // optional folder of mask frames (first channel), as many
  std::string target_mask = "alpha";  // alpha | mask.OB_<name> | mask.CO_<name>
  FlowSource flow = FlowSource::Auto;  // auto: fluid_velocity, else velocity_forward, else masks
  FluidymationOptions options = default_fluidymation_options();
};

class FluidymationJob : public ChainedFrameJob {
 public:
  // Reads and checks every input (FileNotFoundError, ValueError).
  explicit FluidymationJob(FluidymationJobConfig config);
  ~FluidymationJob();

  const std::vector<int>& frames() const override { return config_.frames; }
  const std::vector<std::string>& warnings() const override { return warnings_; }
  const JobInputs& inputs() const override { return inputs_; }
  std::string output_path(int frame) const override;
  // The guide the target's flow is read from (fluid_velocity or
  // velocity_forward); empty when it is made from the masks.
  const std::string& flow_guide() const { return flow_guide_; }
  std::string summary() const override { return "flow from " + (flow_guide_.empty() ? "masks" : flow_guide_); }

  // The first exemplar frame followed by the frames written so far.
  bool has_contact_sheet() const override { return true; }
  void write_contact_sheet(const std::string& path, int columns = 0) const override;

 private:
  std::string state_path(int frame) const;
  std::string record_path(int frame) const;
  bool is_current(std::size_t index) const override;
  // Stylizes frames()[index] from the previous frame's matches (in memory, or
  // read back). progress(fraction) returning false cancels: CancelledError,
  // nothing of the frame written.
  FrameResult make_frame(std::size_t index, const ProgressCallback& progress) override;
  FluidSequence sequence() const;  // views of the exemplar and the target
  const Fluidymation& method();
  void write_frame(std::size_t index, const FluidFrame& frame);

  FluidymationJobConfig config_;
  std::vector<std::string> warnings_;
  JobInputs inputs_;
  std::vector<Image> exemplar_, exemplar_masks_, target_masks_, target_flows_;
  std::string flow_guide_;
  std::vector<std::string> keys_;  // per frame index, chained
  std::unique_ptr<Fluidymation> method_;
  std::vector<FluidFrame> both_ways_;  // the bidirectional solve, once
  std::size_t last_index_ = std::size_t(-1);
  FluidNnf last_nnf_;  // matches of frames()[last_index_]
};

}  // namespace tempera

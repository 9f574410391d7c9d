#pragma once
// The rigid-body method (rigid.hpp) as a job of independent frames over a
// guide cache's tracks.json: `tempera stylize --method rigid` and the
// registry's make_job. The targets are the tracked objects (config.objects,
// or every one), each drawn on its own and laid over the others far to near
// by the tracks' camera depth (the name order without one); the exemplar is a folder with a source
// simulation's tracks.json and its drawn frames drawn/NNNN.png (RGBA ink,
// every frame drawn), a folder of such folders, or "generated": the
// project's own drawn bouncing ball (a box with shape "box"), written once
// beside the frames folder (OUT/exemplar_generated_SHAPE). Each frame is
// written atomically (RGBA, straight alpha; with paper: opaque, on paper),
// then its record (OUT/frames/tempera_rigid/frame_0001.txt); a rerun keeps
// every frame whose record is current and makes the others.
#include <memory>
#include <string>
#include <vector>

#include "tempera/app/frame_job.hpp"
#include "tempera/app/job_config.hpp"
#include "tempera/methods/rigid/quadratic_fit.hpp"
#include "tempera/methods/rigid/rigid.hpp"
#include "tempera/methods/rigid/tracks_file.hpp"

namespace tempera {

constexpr const char* kGeneratedRigidExemplar = "generated";

struct RigidJobConfig : JobConfig {
  std::vector<std::string> objects;  // the target objects; empty: every tracked one
  std::string shape = "circle";  // the objects' proxy: circle | box
  bool paper = false;            // opaque frames on paper instead of RGBA
  std::string strokes;           // a stroke exemplar to re-draw the lines with ("generated" or an image); "" none
  RigidOptions options;          // symmetry: the shape's unless symmetry_given
  bool symmetry_given = false;
  QuadraticFitOptions fit;
};

// An exemplar folder's source track and its drawn frames' paths (every
// frame drawn: checked when read).
struct RigidExemplarFiles {
  Track track;
  std::vector<std::string> drawings;
};

// The track and drawings of the exemplar folder `folder`; ValueError or
// FileNotFoundError naming what is wrong.
RigidExemplarFiles read_rigid_exemplar_files(const std::string& folder);

// The exemplar folders `examples` names: itself when it holds tracks.json,
// else its subfolders that do (sorted). ValueError when there is none.
std::vector<std::string> rigid_exemplar_folders(const std::string& examples);

// The project's own exemplar for `shape` as an exemplar folder
// `folder` (tracks.json and drawn/NNNN.png), written once: the tracks last,
// so that a folder with tracks is whole.
void write_generated_rigid_exemplar(const std::string& folder, const std::string& shape);

class RigidJob : public FrameJob {
 public:
  // Reads and checks the tracks, the exemplars' files and the options.
  explicit RigidJob(RigidJobConfig config);
  ~RigidJob() override;

  const std::vector<int>& frames() const override { return config_.frames; }
  std::string output_path(int frame) const override;
  std::string record_path(int frame) const;
  FrameResult run_frame(std::size_t index, const ProgressCallback& progress = {}) override;
  const JobInputs& inputs() const override { return inputs_; }
  bool has_contact_sheet() const override { return true; }
  void write_contact_sheet(const std::string& path, int columns = 0) const override;

 private:
  struct Solved;  // the fitted exemplars and every frame's deformation, made once
  const Solved& solved(const ProgressCallback& progress);
  void select_objects();
  void check_frames() const;
  std::string take_exemplars();
  void take_strokes();
  void list_inputs();
  std::string frame_key(int frame) const;
  std::vector<std::string> far_to_near(int frame) const;
  Image draw_object(const std::string& name, int frame, const ProgressCallback& progress) const;

  RigidJobConfig config_;
  TracksFile tracks_;
  std::vector<std::string> objects_;  // the targets, sorted
  int width_ = 0, height_ = 0;
  std::vector<std::string> exemplar_folders_;
  std::vector<RigidExemplarFiles> exemplar_files_;  // read once; the generated one when it is written
  JobInputs inputs_;
  Image strokes_;  // the stroke exemplar; empty for none
  std::string settings_;
  std::unique_ptr<Solved> solved_;
};

}  // namespace tempera

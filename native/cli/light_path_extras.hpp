#pragma once
// What `tempera stylize` adds around the frames of a method that matches a
// painting of an exemplar render to the shot by light-path guides (its
// registry entry's light_path_guides: StyLit, the coherent method): the
// exemplar render's guides rendered from --exemplar-scene, the video of the
// frames, and Color Me Noisy's pass that boils them (--noise). One place for
// both commands that run such methods (method_command.cpp,
// stylize_command.cpp).
#include <optional>
#include <string>
#include <vector>

#include "cli_args.hpp"
#include "scene_guides.hpp"
#include "tempera/app/job_config.hpp"
#include "tempera/app/job_inputs.hpp"
#include "tempera/app/light_path_guides.hpp"
#include "tempera/methods/noisy/noisy.hpp"

namespace tempera::cli {

struct LightPathExtras {
  std::string exemplar_scene;  // --exemplar-scene: its guides rendered into OUT/exemplar_guides
  double fps = 24;             // of the video
  bool video = true;           // OUT/stylized.mp4 (and OUT/noisy.mp4)
  NoisyOptions noisy;          // noisy.noise 0: no noise pass
  std::string noise_map;
  std::string noise_reference;  // boil these frames instead of stylizing
  LightPathExtras();
  bool noise() const { return noisy.noise > 0; }
};

// Takes `flag` (reading its value from `r`) if it is one of the extras':
// --exemplar-scene, --fps, --no-video, --noise-map, --noise-reference and
// Color Me Noisy's options (--noise, ...). False for any other flag.
bool take_light_path_flag(LightPathExtras& extras, const std::string& flag, ArgReader& r);

// The checks at parse time, before anything is rendered or stylized (the
// noise pass runs last: its exemplar's size is checked now). `segment`: a
// farm task of the coherent method, which may not boil. ValueError.
void check_light_path_extras(const LightPathExtras& extras, const JobConfig& config, bool segment = false);

// Help lines of the extras' flags.
std::string light_path_extras_help();

// Renders frame `frame` of the exemplar scene into OUT/exemplar_guides;
// returns that folder. CancelledError when interrupted.
std::string render_exemplar_scene(const LightPathExtras& extras, const GuideRender& how, const std::string& out,
                                  int frame);

// OUT/stylized.mp4 from OUT/frames when the frames are consecutive PNGs and
// the video is wanted (a line says why not otherwise); a file that cannot be
// written is a warning.
void write_video(const LightPathExtras& extras, const JobInputs& inputs, const JobConfig& config);

// What the noise pass reads besides the extras: the shot's inputs, and the
// light-path guides' weights, seed and threads given to the method.
struct NoisePassInputs {
  JobConfig config;  // exemplar, guides, frames, out (the command's OUT), resume
  std::string exemplar_guides;
  std::optional<int> exemplar_frame;
  GuideWeights weights = default_guide_weights();
  SynthesisOptions synthesis;  // its seed and threads
};

// The coherent frames (OUT/frames, or --noise-reference) boiled into
// OUT/noisy, resumable like the stylization, and OUT/noisy.mp4; false if
// interrupted.
bool run_noise_pass(const LightPathExtras& extras, const NoisePassInputs& inputs);

bool consecutive(const std::vector<int>& frames);

}  // namespace tempera::cli

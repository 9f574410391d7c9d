#include "tempera/methods/noisy/noisy_method.hpp"

#include "tempera/app/light_path_guides.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/methods/noisy/noisy_sequence.hpp"

namespace tempera {
namespace {

const char* kDetails =
    "The shot's render (the guide cache's FULL guide, Cycles' Combined pass, in display sRGB)\n"
    "boiled like hand-coloured animation (Color Me Noisy, Fiser et al. 2014): below the width\n"
    "--noise the frames follow the render, above it the medium's texture is synthesized again\n"
    "every frame. The medium (--exemplar, a still) must have the render's colours, as in the\n"
    "paper's 3D examples, whose materials are textured from it; left out, it is the first\n"
    "frame's render under a paper grain. --reference boils a folder of coherent frames instead\n"
    "(frame_0001.png ...; it needs --exemplar).\n"
    "\n"
    "outputs:\n"
    "  OUT/frames/frame_0001.png ...     the frames, each written atomically\n"
    "  OUT/frames/.tempera_noisy/        a resume record per frame\n"
    "  OUT/contact_sheet.png             the medium followed by the frames\n"
    "\n"
    "Resume: a frame is skipped when its output and record are current (same settings, medium\n"
    "and guide or reference frame); frames are independent, so a farm may split them anywhere.\n";

const char* kInputsHelp =
    "  --reference DIR         coherent frames to boil instead of the render (frame_0001.png ...)\n"
    "  --noise-map FILE|GUIDE  where the noise goes: an image, or a guide (alpha, mask.OB_Name,\n"
    "                          an AOV); 0 = the render as it is, 1 = --noise\n"
    "  --exemplar-guides DIR   guide cache of the exemplar render (for --noise-guides)\n"
    "  --exemplar-frame N      its frame (default: the only frame in --exemplar-guides)\n"
    "  --weights NAME=W,...    light-path guide weights for --noise-guides (as --method stylit)\n";

std::string value_of(const std::string& flag, const std::string& text) {
  if (text.empty()) throw ValueError(concat("--", flag, " needs a value"));
  return text;
}

NoisySequenceConfig job_config(const JobConfig& given, const MethodOptions& options) {
  NoisySequenceConfig config;
  static_cast<JobConfig&>(config) = given;
  for (const auto& [flag, text] : options) {
    if (flag == "reference") config.reference = value_of(flag, text);
    else if (flag == "noise-map") config.noise_map = value_of(flag, text);
    else if (flag == "exemplar-guides") config.exemplar_guides = value_of(flag, text);
    else if (flag == "exemplar-frame") config.exemplar_frame = parse_number<int>(text, "--exemplar-frame");
    else if (flag == "weights") parse_guide_weights(value_of(flag, text), config.guide_weights);
    else if (!set_from_text(config.options, noisy_option_table(), flag, text) &&
             !set_from_text(config.options.synthesis, synthesis_option_table(), flag, text))
      throw unknown_method_option("noisy", flag);
  }
  return config;
}

}  // namespace

MethodEntry noisy_method() {
  MethodEntry m;
  m.name = "noisy";
  m.title = "Temporal Noise (Color Me Noisy)";
  m.summary =
      "The render boiled like hand-coloured animation: its large shapes kept, a medium's texture synthesized "
      "again every frame, by an amount set with Noise (Fišer 2014)";
  m.paper = "Fišer et al. 2014";
  m.unit = "frame";
  m.docs = "docs/noisy.md";
  m.make_job = [](const JobConfig& config, const MethodOptions& options) {
    return std::make_unique<NoisySequence>(job_config(config, options));
  };
  m.check_options = [](const MethodOptions& options) {
    const NoisySequenceConfig c = job_config({}, options);
    validate_noisy_options(c.options);
    validate(c.options.synthesis);
  };
  m.options_help = kInputsHelp + flags_help<NoisyOptions>(noisy_option_table(), true) +
                   "  (any engine option of 'tempera synth --help'; defaults: 7x7 patches, voting by\n"
                   "  mode, 4 EM x 2 PatchMatch per level, no usage control)\n";
  m.default_exemplar = kJobMadeExemplar;  // the first render under a paper grain (render_medium.hpp)
  m.help_details = kDetails;
  return m;
}

}  // namespace tempera

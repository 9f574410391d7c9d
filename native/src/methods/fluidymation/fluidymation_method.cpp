#include "tempera/methods/fluidymation/fluidymation_method.hpp"

#include "tempera/engine/error.hpp"
#include "tempera/methods/fluidymation/fluidymation_job.hpp"

namespace tempera {
namespace {

const char* kDetails =
    "The target's masks painted with the motion of a natural medium filmed or simulated as a\n"
    "video exemplar (ink, watercolour). --exemplar is a folder of frames (PNG, EXR, ...; name\n"
    "order); RGBA: the alpha is the paint's mask, RGB: give --exemplar-masks. The exemplar's flow\n"
    "comes from its masks; the target's from the guide cache's fluid_velocity or\n"
    "velocity_forward, or from its masks (--flow). Frames must be consecutive.\n"
    "\n"
    "outputs:\n"
    "  OUT/frames/frame_0001.png ...     RGBA frames (alpha = the target mask), each written atomically\n"
    "  OUT/frames/tempera_fluidymation/  per frame the matches and a resume record\n"
    "  OUT/contact_sheet.png             the first exemplar frame followed by the frames\n"
    "\n"
    "Resume: a frame is skipped when its output, matches and record are current (same settings,\n"
    "files and every frame before it); rerun the same command after an interruption.\n";

const char* kInputsHelp =
    "  --exemplar-masks DIR    mask frames of the exemplar (first channel > 0.5 = paint)\n"
    "  --target-mask NAME      alpha (default) | mask.OB_<object> | mask.CO_<collection>\n"
    "  --flow F                auto (default: fluid, else guides, else masks, by what the cache\n"
    "                          has) | fluid (fluid_velocity: smoke, liquids) | guides\n"
    "                          (velocity_forward, exact from Blender) | masks (App. A)\n";

std::string value_of(const std::string& flag, const std::string& text) {
  if (text.empty()) throw ValueError(concat("--", flag, " needs a value"));
  return text;
}

FluidymationJobConfig job_config(const JobConfig& given, const MethodOptions& options) {
  FluidymationJobConfig config;
  static_cast<JobConfig&>(config) = given;
  for (const auto& [flag, text] : options) {
    if (flag == "exemplar-masks") config.exemplar_masks = value_of(flag, text);
    else if (flag == "target-mask") config.target_mask = value_of(flag, text);
    else if (flag == "flow") config.flow = parse_enum<FlowSource>(value_of(flag, text), "--flow");
    else if (!set_from_text(config.options, fluidymation_option_table(), flag, text) &&
             !set_from_text(config.options.synthesis, synthesis_option_table(), flag, text))
      throw unknown_method_option("fluidymation", flag);
  }
  return config;
}

}  // namespace

MethodEntry fluidymation_method() {
  MethodEntry m;
  m.name = "fluidymation";
  m.title = "Natural Media (Fluidymation)";
  m.summary =
      "A moving object or collection rendered as a filmed medium (ink, watercolour) spreading along its motion, "
      "from a video exemplar with masks (Platkevič 2021); RGBA frames over the render";
  m.paper = "Platkevič et al. 2021";
  m.unit = "chained frame";
  m.docs = "docs/fluidymation.md";
  m.make_job = [](const JobConfig& config, const MethodOptions& options) {
    return std::make_unique<FluidymationJob>(job_config(config, options));
  };
  m.check_options = [](const MethodOptions& options) { validate(job_config({}, options).options); };
  m.options_help = kInputsHelp + flags_help<FluidymationOptions>(fluidymation_option_table(), true) +
                   "  (any engine option of 'tempera synth --help'; defaults: 5x5 patches, directed\n"
                   "  orientations, 3 EM iterations, exact guides)\n";
  m.default_exemplar = "ink";
  m.help_details = kDetails;
  return m;
}

}  // namespace tempera

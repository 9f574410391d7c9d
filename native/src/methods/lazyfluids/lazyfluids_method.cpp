#include "tempera/methods/lazyfluids/lazyfluids_method.hpp"

#include "tempera/engine/error.hpp"
#include "tempera/methods/lazyfluids/lazyfluids_job.hpp"

namespace tempera {
namespace {

const char* kDetails =
    "The exemplar is an RGBA image of a fluid element (smoke, fire, ink), or a folder of RGBA\n"
    "frames (a video exemplar, sorted by name, looped when shorter than the shot). It is carried\n"
    "along the flow inside the target alpha, every exemplar patch used equally often per\n"
    "boundary / interior segment so that it never washes out. Target alpha: the guide cache's\n"
    "'alpha'; flow: 'fluid_velocity' (p moves to p + F in the next frame), else\n"
    "'velocity_forward', else zero (with a warning). Frames must be consecutive.\n"
    "\n"
    "outputs:\n"
    "  OUT/frames/frame_0001.png ...     RGBA frames, transparent outside (each written atomically)\n"
    "  OUT/frames/tempera_lazyfluids/    per frame the float state and the resume record\n"
    "  OUT/contact_sheet.png             the exemplar followed by the frames\n"
    "\n"
    "Resume: a frame is skipped when its record matches the settings, the exemplar, its guide\n"
    "files and the frame before; rerun the same command after an interruption (Ctrl-C stops\n"
    "within the current frame; finished frames are kept).\n";

LazyFluidsJobConfig job_config(const JobConfig& given, const MethodOptions& options) {
  LazyFluidsJobConfig config;
  static_cast<JobConfig&>(config) = given;
  for (const auto& [flag, text] : options)
    if (!set_from_text(config.options, lazyfluids_option_table(), flag, text) &&
        !set_from_text(config.options.synthesis, synthesis_option_table(), flag, text))
      throw unknown_method_option("lazyfluids", flag);
  return config;
}

}  // namespace

MethodEntry lazyfluids_method() {
  MethodEntry m;
  m.name = "lazyfluids";
  m.title = "Fluid (LazyFluids)";
  m.summary =
      "Smoke, fire and liquids painted from an RGBA exemplar carried along the fluid's flow, its texture kept "
      "fresh by uniform patch usage (Jamriška 2015); RGBA frames over the render";
  m.paper = "Jamriška et al. 2015";
  m.unit = "chained frame";
  m.docs = "docs/lazyfluids.md";
  m.make_job = [](const JobConfig& config, const MethodOptions& options) {
    return std::make_unique<LazyFluidsJob>(job_config(config, options));
  };
  m.check_options = [](const MethodOptions& options) { validate(job_config({}, options).options); };
  m.options_help = flags_help<LazyFluidsOptions>(lazyfluids_option_table(), true) +
                   "  (any engine option of 'tempera synth --help'; LazyFluids' defaults: --patch-size 5\n"
                   "  --usage uniform)\n";
  m.default_exemplar = "smoke";
  m.help_details = kDetails;
  return m;
}

}  // namespace tempera

#include "tempera/methods/stylit/stylit_method.hpp"

#include "tempera/app/light_path_guides.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/methods/stylit/stylize_job.hpp"

namespace tempera {
namespace {

const char* kDetails =
    "The painting (--exemplar) is made on the exemplar render, whose light-path guides\n"
    "(--exemplar-guides, or --exemplar-scene rendered by Blender) are matched to the shot's.\n"
    "\n"
    "outputs:\n"
    "  OUT/frames/frame_0001.png ...   stylized frames (each written atomically)\n"
    "  OUT/frames/tempera_stylize.json settings, resume key and flicker per frame\n"
    "  OUT/contact_sheet.png           the painting followed by the frames\n"
    "  OUT/stylized.mp4                H.264 video (needs ffmpeg on PATH; PNG frames)\n"
    "\n"
    "Resume: a frame is skipped when its output exists and was made with the same settings,\n"
    "painting and guide files (sizes and modification times); rerun the same command after\n"
    "an interruption. Ctrl-C stops within the current frame; finished frames are kept.\n"
    "Runs sharing one --out (a render farm) each add their frames to the record under a\n"
    "lock; a damaged record is set aside with a warning and its frames are redone.\n";

// StyLit's flags: the exemplar render's guides, the guide weights with their
// defaults from the guide table, its option table and the engine's.
std::string options_help() {
  std::string defaults;
  for (const auto& g : light_path_guides()) defaults += concat(defaults.empty() ? "" : ",", g.name, "=", format_value(g.weight));
  return concat(
      "  --exemplar-guides DIR   guide cache of the exemplar render (or --exemplar-scene FILE)\n"
      "  --exemplar-frame N      frame of the exemplar (default: 1 with --exemplar-scene,\n"
      "                          else the only frame in --exemplar-guides)\n"
      "  --weights LIST          light-path guide weights (default ", defaults, ");\n"
      "                          guides not listed keep their default, 0 leaves a guide out\n",
      flags_help<StylitOptions>(stylit_option_table()),
      "  --usage MODE            none | penalty | uniform | budget (default budget)\n"
      "  --patch-size N          odd patch width (default 5)\n"
      "  --seed N                random seed (default 1)\n"
      "  --threads N             worker threads (default 0 = all cores)\n"
      "  (any engine option of 'tempera synth --help', e.g. --em-iters 4 --window-sigma 3)\n");
}

// The core's config and StyLit's own options, as `tempera stylize` takes
// them: the exemplar render's guide cache and frame, the guide weights,
// StyLit's options (--temporal, --quality) and any engine option.
StylizeJobConfig job_config(const JobConfig& given, const MethodOptions& options) {
  StylizeJobConfig config;
  static_cast<JobConfig&>(config) = given;
  for (const auto& [flag, text] : options) {
    if (flag == "exemplar-guides") config.exemplar_guides = text;
    else if (flag == "exemplar-frame") config.exemplar_frame = parse_number<int>(text, "--exemplar-frame");
    else if (flag == "weights") parse_guide_weights(text, config.stylit.weights);
    else if (!set_from_text(config.stylit, stylit_option_table(), flag, text) &&
             !set_from_text(config.stylit.synthesis, synthesis_option_table(), flag, text))
      throw unknown_method_option("stylit", flag);
  }
  validate(config.stylit.synthesis);
  active_guides(config.stylit);  // errors now, not in the middle of a run
  return config;
}

}  // namespace

MethodEntry stylit_method() {
  MethodEntry m;
  m.name = "stylit";
  m.title = "Per-Frame StyLit";
  m.summary =
      "Each frame painted on its own from the light-path guides (with the temporal guide's pull towards the "
      "previous frame); frames split anywhere over machines";
  m.paper = "Fišer et al. 2016";
  m.unit = "frame";
  m.light_path_guides = true;
  m.default_exemplar = kKitExemplar;  // the painted sphere on a table
  m.docs = "docs/user_guide.md";
  m.make_job = [](const JobConfig& config, const MethodOptions& options) {
    return std::make_unique<StylizeJob>(job_config(config, options));
  };
  m.check_options = [](const MethodOptions& options) { job_config({}, options); };
  m.options_help = options_help();
  m.help_details = kDetails;
  return m;
}

}  // namespace tempera

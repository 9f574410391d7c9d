#include "tempera/methods/rigid/rigid_method.hpp"

#include "tempera/methods/rigid/rigid_exemplar.hpp"
#include "tempera/methods/rigid/rigid_job.hpp"

namespace tempera {
namespace {

const char* kDetails =
    "The guide cache (--guides) holds tracks.json, the target rigid-body simulation's tracks\n"
    "(rendering the guides of a scene with a baked rigid-body world writes it), and\n"
    "manifest.json (the frame size). The exemplar is a folder with a source simulation's\n"
    "tracks.json and its drawn frames drawn/0001.png ... (RGBA ink, numbered from the tracks'\n"
    "frame_start, every frame drawn), or a folder of such folders; 'generated' (the default) is\n"
    "the project's own drawn bouncing ball (a box with --shape box), written once into\n"
    "OUT/exemplar_generated_SHAPE.\n"
    "\n"
    "outputs:\n"
    "  OUT/frames/frame_0001.png ...     RGBA frames, straight alpha (--paper: opaque, on paper),\n"
    "                                    each written atomically\n"
    "  OUT/frames/tempera_rigid/         the resume record of each frame\n"
    "  OUT/contact_sheet.png             a drawn exemplar frame followed by the frames\n"
    "\n"
    "Resume: a frame is skipped when its record matches the settings, the tracks and the\n"
    "drawn frames; rerun the same command after an interruption. No file is ever deleted.\n";

const char* kJobOptionsHelp =
    "  --object NAME           a target object (repeatable; default every tracked object, each drawn\n"
    "                          on its own and laid over the others far to near by camera depth)\n"
    "  --shape MODE            the objects' proxy [circle, box] (default circle)\n"
    "  --paper [V]             opaque frames on paper instead of RGBA (default false)\n"
    "  --strokes IMAGE         re-draw the lines from this stroke exemplar (an RGBA image of strokes,\n"
    "                          or 'generated': the project's blue brush pen) on a stroke-position guide\n";

bool yes(const std::string& flag, const std::string& text) {
  if (text.empty() || text == "true") return true;
  if (text == "false") return false;
  throw ValueError(concat("--", flag, " takes true or false, got '", text, "'"));
}

RigidJobConfig job_config(const JobConfig& given, const MethodOptions& options) {
  RigidJobConfig config;
  static_cast<JobConfig&>(config) = given;
  if (config.exemplar.empty()) config.exemplar = kGeneratedRigidExemplar;
  for (const auto& [flag, text] : options) {
    const auto value = [&, &flag = flag, &text = text] {
      if (text.empty()) throw ValueError(concat("--", flag, " needs a value"));
      return text;
    };
    if (flag == "object") config.objects.push_back(value());
    else if (flag == "shape") config.shape = enum_name(parse_enum<ProxyShape>(value(), "proxy shape"));
    else if (flag == "paper") config.paper = yes(flag, text);
    else if (flag == "strokes") config.strokes = value();
    else if (set_from_text(config.options, rigid_option_table(), flag, text)) config.symmetry_given |= flag == "symmetry";
    else if (!set_from_text(config.fit, quadratic_fit_option_table(), flag, text)) throw unknown_method_option("rigid", flag);
  }
  return config;
}

}  // namespace

MethodEntry rigid_method() {
  MethodEntry m;
  m.name = "rigid";
  m.title = "Rigid Bodies (hand-drawn)";
  m.summary =
      "The squash, stretch and line of drawn examples carried onto the scene's rigid-body simulation "
      "(Dvorožňák 2017; needs a baked rigid-body world)";
  m.paper = "Dvorožňák et al. 2017";
  m.unit = "frame";
  m.light_path_guides = false;
  m.docs = "docs/rigid_bodies.md";
  m.make_job = [](const JobConfig& config, const MethodOptions& options) {
    return std::make_unique<RigidJob>(job_config(config, options));
  };
  m.check_options = [](const MethodOptions& options) {
    const RigidJobConfig c = job_config({}, options);
    validate_fields(c.options, rigid_option_table());
    validate_fields(c.fit, quadratic_fit_option_table());
  };
  m.options_help = kJobOptionsHelp + flags_help<RigidOptions>(rigid_option_table(), true) +
                   flags_help<QuadraticFitOptions>(quadratic_fit_option_table(), true);
  m.default_exemplar = kJobMadeExemplar;  // its job draws the generated exemplar
  m.help_details = kDetails;
  return m;
}

}  // namespace tempera

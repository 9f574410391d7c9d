#include "tempera/methods/stylit/stylit_method.hpp"

#include "tempera/app/light_path_guides.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/methods/stylit/stylize_job.hpp"

namespace tempera {
namespace {

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
  if (config.exemplar_guides.empty())
    throw ValueError("--exemplar-guides is required (the guide cache of the exemplar render)");
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
  m.docs = "docs/user_guide.md";
  m.make_job = [](const JobConfig& config, const MethodOptions& options) {
    return std::make_unique<StylizeJob>(job_config(config, options));
  };
  return m;
}

}  // namespace tempera

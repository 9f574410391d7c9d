#include "commands.hpp"

#include "tempera/engine/error.hpp"

namespace tempera::cli {

std::map<std::string, Command>& commands() {
  static std::map<std::string, Command> table = {
      {"synth", {"guided patch synthesis of one image (StyLit / image analogies)", run_synth}},
      {"render-guides", {"render a .blend scene's guide cache with background Blender", run_render_guides}},
      {"stylize", {"stylize an animation by example, with any method (--method; resumable)", run_stylize}},
  };
  return table;
}

CommandRegistration::CommandRegistration(const std::string& name, std::string summary,
                                         std::function<int(const Args&)> run) {
  // Static initialization: a clash cannot be reported, so it must not build silently wrong.
  if (!commands().emplace(name, Command{std::move(summary), std::move(run)}).second)
    throw ValueError(concat("the command '", name, "' is registered twice"));
}

}  // namespace tempera::cli

#include "scene_guides.hpp"

#include <filesystem>
#include <iostream>

#include "frame_loop.hpp"
#include "tempera/engine/error.hpp"

namespace fs = std::filesystem;

namespace tempera::cli {

void render_scene_guides(const GuideRender& how, const std::string& scene, const std::string& frames,
                         const std::string& out) {
  Args options = {"--frames", frames, "--out", out};
  if (!how.samples.empty()) options.insert(options.end(), {"--samples", how.samples, "--ld12e-samples", how.samples});
  std::cerr << "tempera stylize: rendering the guides of " << scene << " (frames " << frames << ") into " << out
            << "\n";
  const int status = render_guides_in_blender(how.blender, scene, options, interrupt_flag());
  if (interrupted()) throw CancelledError("interrupted while rendering guides");
  if (status == 2) throw ValueError(concat("rendering the guides of '", scene, "' failed: bad values (see above)"));
  if (status != 0) throw IoError(concat("rendering the guides of '", scene, "' failed (see above)"));
}

Args with_scene_guides(const Args& args) {
  if (args.empty() || args[0].rfind("--", 0) == 0 || ArgReader(args, "stylize").wants_help()) return args;
  const std::string scene = args[0];
  GuideRender how;
  Args rest;
  std::string frames, out, guides;
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool valued = i + 1 < args.size();
    if (a == "--samples" && valued) how.samples = args[++i];
    else if (a == "--blender" && valued) how.blender.blender = args[++i];
    else if (a == "--addon-path" && valued) how.blender.addon = args[++i];
    else {
      if (valued && a == "--frames") frames = args[i + 1];
      if (valued && a == "--out") out = args[i + 1];
      if (valued && a == "--guides") guides = args[i + 1];
      rest.push_back(a);
    }
  }
  if (frames.empty()) throw ValueError("--frames is required (e.g. --frames 1-48)");
  if (out.empty()) throw ValueError("--out is required (the output folder)");
  if (guides.empty()) {
    guides = (fs::path(out) / "guides").string();
    rest.insert(rest.end(), {"--guides", guides});
  }
  catch_interrupts();
  render_scene_guides(how, scene, frames, guides);
  return rest;
}

}  // namespace tempera::cli

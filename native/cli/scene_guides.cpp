#include "scene_guides.hpp"

#include <iostream>

#include "frame_loop.hpp"
#include "tempera/engine/error.hpp"

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

}  // namespace tempera::cli

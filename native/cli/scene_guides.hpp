#pragma once
// `tempera stylize SCENE.blend ...`: the scene's guide cache rendered first,
// in background Blender with render-guides' renderer, so that every method
// that reads a guide cache runs from a .blend in one command.
#include <string>

#include "cli_args.hpp"

namespace tempera::cli {

// How the guides are rendered: which Blender, and the Cycles samples ("" = render-guides' default).
struct GuideRender {
  BlenderSetup blender = default_blender_setup();
  std::string samples;
};

// Renders `frames` of `scene` into the guide cache `out`; frames already
// current are reused. ValueError for bad values, IoError when Blender fails,
// CancelledError when interrupted (SIGINT, SIGTERM: Blender is stopped too).
void render_scene_guides(const GuideRender& how, const std::string& scene, const std::string& frames,
                         const std::string& out);

}  // namespace tempera::cli

// `tempera render-guides SCENE.blend --frames A-B --out DIR [...]`: renders a
// scene's guide cache by running Blender in the background on the file (which
// is opened, never written) with the add-on's guide renderer.
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "cli_args.hpp"
#include "frame_loop.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/app/paths.hpp"
#include "tempera/app/process.hpp"

namespace fs = std::filesystem;

namespace tempera::cli {
namespace {

const char* kRenderGuidesHelp =
    "usage: tempera render-guides SCENE.blend --frames A-B --out DIR [options]\n"
    "\n"
    "Renders the guides of SCENE (light paths, velocities, occlusion, orientation, masks,\n"
    "lines) with Cycles in background Blender into the guide cache DIR: one multilayer EXR\n"
    "per frame plus manifest.json (docs/guide_cache.md). Frames already current are skipped.\n"
    "The .blend file is only read; its own engine, resolution and settings are respected\n"
    "(guides are rendered at the scene's effective resolution).\n"
    "\n"
    "options:\n"
    "  --frames RANGE          frames to render, e.g. 1-24 or 1-10,15\n"
    "  --out DIR               guide cache folder\n"
    "  --scene NAME            scene in the file (default: its active scene)\n"
    "  --samples N             Cycles samples of the main render (default 16)\n"
    "  --ld12e-samples N       samples of the LD{1,2}E render (default 16)\n"
    "  --seed N                Cycles seed (default 0)\n"
    "  --epsilon E             occlusion tolerance, squared pixels (default 2)\n"
    "  --tensor-sigma S        structure tensor smoothing, pixels (default 2)\n"
    "  --line-depth-threshold T, --line-normal-angle DEG, --d-max D   line guide\n"
    "  --masks MODE            objects+collections | objects | collections | none\n"
    "  --orientation-aov NAME  Color shader AOV holding the artist's stroke directions\n"
    "  --lpe EXPR              also trace this light path expression as a guide (repeatable),\n"
    "                          e.g. --lpe 'L.*SDE' --lpe 'LD{2}E' (docs/lpe_guides.md)\n"
    "  --lpe-samples N         path-tracer samples per pixel of each expression (default 64)\n"
    "  --blender PATH          Blender to run (default: $TEMPERA_BLENDER or 'blender')\n"
    "  --addon-path DIR        folder holding the tempera package\n"
    "                          (default: $TEMPERA_ADDON_PATH or this build's addon folder)\n";


std::string env_or(const char* name, const std::string& fallback) {
  const char* value = std::getenv(name);
  return value && *value ? value : fallback;
}

}  // namespace

BlenderSetup default_blender_setup() {
  return {env_or("TEMPERA_BLENDER", "blender"),
          env_or("TEMPERA_ADDON_PATH", fs::path(TEMPERA_PYTHON_PACKAGE_DIR).parent_path().string())};
}

int render_guides_in_blender(const BlenderSetup& setup, const std::string& scene, const Args& options,
                             const volatile std::sig_atomic_t* interrupted) {
  std::error_code ec;
  if (!fs::is_regular_file(scene, ec)) throw FileNotFoundError(concat("scene file not found: '", scene, "'"));
  if (!fs::is_directory(fs::path(setup.addon) / "tempera", ec))
    throw FileNotFoundError(concat("no tempera package in '", setup.addon, "' (pass --addon-path)"));
  const bool found = setup.blender.find('/') != std::string::npos ? access(setup.blender.c_str(), X_OK) == 0
                                                                   : !find_on_path(setup.blender).empty();
  if (!found)
    throw FileNotFoundError(concat("cannot run '", setup.blender, "' (install Blender or pass --blender PATH)"));
  // The package path travels as an argument, not inside the Python code, so
  // no quoting of paths is ever needed.
  const std::string bootstrap =
      "import sys; sys.path.insert(0, sys.argv[sys.argv.index('--') + 1]); "
      "del sys.argv[sys.argv.index('--') + 1]; "
      "from tempera.blender.render_guides_main import main; main()";
  // Absolute, so that Blender cannot read the scene as one of its options: a file
  // named '-P' would make it run the next argument as Python, '-a' start its player.
  const std::string scene_path = fs::absolute(scene).string();
  std::vector<std::string> argv = {setup.blender, "-b", "--factory-startup", scene_path, "--python-exit-code", "1",
                                   "--python-expr", bootstrap, "--", setup.addon};
  argv.insert(argv.end(), options.begin(), options.end());
  const int status = run_process(argv, false, interrupted);
  // The renderer (render_guides_main.py) prints its own error line and exits
  // 2 (bad values), 3 (files) or 130 (interrupted); anything else means
  // Blender failed before or around it (or is not Blender) and said nothing.
  switch (status) {
    case 0:
    case 2:
    case 130: return status;
    case 3: return 1;
    case 127:
      std::cerr << "tempera: cannot run '" << setup.blender << "' (install Blender or pass --blender PATH)\n";
      return 1;
    default:
      if (*interrupted) return kInterruptedStatus;  // Ctrl-C: Blender's own exit status says nothing more
      std::cerr << "tempera: Blender ('" << setup.blender << "') exited with status " << status
                << " while rendering the guides of '" << scene << "'"
                << (status > 128 ? " (killed by a signal)" : "") << "\n";
      return 1;
  }
}

int run_render_guides(const Args& args) {
  ArgReader in(args, "render-guides");
  if (in.wants_help() || args.empty()) {
    std::cout << kRenderGuidesHelp;
    return args.empty() ? 2 : 0;
  }
  const std::string scene = args[0];
  if (scene.rfind("--", 0) == 0) throw ValueError("the first argument must be the .blend file");
  BlenderSetup setup = default_blender_setup();
  Args forwarded;
  bool has_frames = false, has_out = false;
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    if ((a == "--blender" || a == "--addon-path") && i + 1 < args.size()) {
      (a == "--blender" ? setup.blender : setup.addon) = args[++i];
      continue;
    }
    has_frames |= a == "--frames";
    has_out |= a == "--out";
    forwarded.push_back(a);
  }
  std::error_code ec;
  if (!fs::is_regular_file(scene, ec)) throw FileNotFoundError(concat("scene file not found: '", scene, "'"));
  if (!has_frames) throw ValueError("--frames is required (e.g. --frames 1-24)");
  if (!has_out) throw ValueError("--out is required (the guide cache folder)");
  // Ctrl-C reaches Blender too (same process group), a farm's SIGTERM only
  // this process, which then stops Blender; either way it waits for Blender
  // to stop and says what is kept, instead of dying silently first.
  catch_interrupts();
  const int status = render_guides_in_blender(setup, scene, forwarded, interrupt_flag());
  if (interrupted()) {
    std::cerr << "tempera render-guides: interrupted; the frames finished so far are in the cache "
                 "(rerun the same command to render the rest)\n";
    return kInterruptedStatus;
  }
  return status;
}

std::vector<int> parse_frames(const std::string& text) {
  const char* hint = " (write e.g. 1-24 or 1-10,15)";
  std::vector<int> frames;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string part = text.substr(start, end - start);
    if (part.empty()) throw ValueError(concat("empty part in frame range '", text, "'", hint));
    const std::size_t dash = part.find('-', 1);
    int first = 0, last = 0;
    const auto read = [&](const std::string& number, int& out) {
      long long value = 0;
      const auto [ptr, ec] = std::from_chars(number.data(), number.data() + number.size(), value);
      if (ec != std::errc() || ptr != number.data() + number.size() || number.empty())
        throw ValueError(concat("cannot read '", part, "' in frame range '", text, "'", hint));
      // Bounded by Blender's frame range: no range is endless, none holds a
      // frame Blender would render as another (it clamps to its last frame).
      if (value < 0 || value > kMaxFrame)
        throw ValueError(concat("frame ", number, " in '", text, "' is outside 0-", kMaxFrame,
                                " (the frames Blender can render)"));
      out = int(value);
    };
    read(part.substr(0, dash), first);
    if (dash == std::string::npos) last = first;
    else read(part.substr(dash + 1), last);
    if (last < first) throw ValueError(concat("frame range '", part, "' ends before it starts"));
    for (int f = first; f <= last; ++f) frames.push_back(f);
    start = end + 1;
  }
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  return frames;
}

}  // namespace tempera::cli

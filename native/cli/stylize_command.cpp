// `tempera stylize`: a whole shot in one command. The overview's help, and
// each method sent to the registry's one command (method_command.cpp), or
// named to the Python package when it runs there.
#include <algorithm>
#include <iostream>
#include <string>

#include "cli_args.hpp"
#include "light_path_extras.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/methods/registry.hpp"

namespace tempera::cli {
namespace {

const char* kStylizeHelpText =
    "usage: tempera stylize SCENE.blend --exemplar STYLE.png (--exemplar-scene EXEMPLAR.blend |\n"
    "                       --exemplar-guides DIR) --frames A-B --out DIR [options]\n"
    "       tempera stylize --guides DIR --exemplar STYLE.png --exemplar-guides DIR --frames A-B\n"
    "                       --out DIR [options]\n"
    "       tempera stylize --method M --help   (each method's inputs and options)\n"
    "\n"
    "Stylizes an animation with StyLit (light-path guides) from a painted exemplar, or with\n"
    "another method (--method). With SCENE.blend the scene's guides are rendered first with\n"
    "background Blender into --guides (default OUT/guides), and with --exemplar-scene the\n"
    "exemplar's guides into OUT/exemplar_guides; guide frames already current are reused.\n"
    "The second form needs no Blender: it reads existing guide caches (render farms).\n"
    "\n"
    "@DETAILS@"
    "\n"
    "inputs:\n"
    "  --exemplar FILE         the painting, made on the exemplar render (same aspect)\n"
    "  --guides DIR            guide cache of the animation (default OUT/guides with SCENE)\n"
    "  --frames RANGE          frames to stylize, e.g. 1-24 or 1-10,15\n"
    "  --out DIR               output folder\n"
    "  --format F              png (default) | exr (float, linear as painted)\n"
    "  --no-resume             stylize every frame again, even if current\n"
    "@EXTRAS@"
    "\n"
    "method:\n"
    "  --method M              the method (default stylit); each has its own options\n"
    "                          (tempera stylize --method M --help):\n"
    "@METHODS@"
    "@LIGHT_PATH_METHODS@"
    "\n"
    "guide rendering (SCENE.blend / --exemplar-scene only):\n"
    "  --samples N             Cycles samples of the guide renders (default 16)\n"
    "  --blender PATH          Blender to run (default: $TEMPERA_BLENDER or 'blender')\n"
    "  --addon-path DIR        folder holding the tempera package\n"
    "  --max-image-pixels N    refuse images declaring more pixels (default 50000000;\n"
    "                          also $TEMPERA_MAX_IMAGE_PIXELS)\n"
    "\n"
    "Exit status: 0 done, 1 error (files, Blender), 2 bad usage or bad values, 130 interrupted.\n";

// One line per method of the registry: its name and title ("stylit  Per-Frame StyLit").
std::string methods_help() {
  std::string out;
  for (const MethodEntry& m : method_registry()) {
    std::string name = "                            " + m.name;
    name.resize(std::max<std::size_t>(name.size() + 1, 42), ' ');
    out += concat(name, m.title, "\n");
  }
  return out;
}

// The options of each method that matches a painting by light-path guides,
// under its title: the methods this overview is about.
std::string light_path_methods_help() {
  std::string out;
  for (const MethodEntry& m : method_registry())
    if (m.light_path_guides) out += concat("\n", m.title, " (--method ", m.name, "):\n", m.options_help);
  return out;
}

// The overview: the default method's outputs and resume, the core's flags,
// the light-path extras, the methods, and the light-path methods' options
// (their registry entries').
std::string stylize_help() {
  std::string text = kStylizeHelpText;
  const auto put = [&](const std::string& key, const std::string& value) { text.replace(text.find(key), key.size(), value); };
  put("@DETAILS@", find_method(method_of({})).help_details);  // its outputs and resume
  put("@EXTRAS@", light_path_extras_help());
  put("@METHODS@", methods_help());
  put("@LIGHT_PATH_METHODS@", light_path_methods_help());
  return text;
}

bool names_a_method(const Args& args) { return std::find(args.begin(), args.end(), "--method") != args.end(); }

}  // namespace

std::string method_of(const Args& args) {
  std::string method = default_method().name;
  for (std::size_t i = 0; i + 1 < args.size(); ++i)
    if (args[i] == "--method") method = args[i + 1];
  return method;
}

int run_stylize(const Args& args) {
  if (args.empty() || (ArgReader(args, "stylize").wants_help() && !names_a_method(args))) {
    std::cout << stylize_help();  // the overview
    return args.empty() ? 2 : 0;
  }
  const MethodEntry& method = find_method(method_of(args));
  return run_registered_method(method, args);
}

}  // namespace tempera::cli

// `tempera`: the batch command line. Runs the native solvers on files on disk,
// with no Blender and no Python, so a render farm can split work by frames.
#include <cstring>
#include <functional>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "cli_args.hpp"
#include "tempera/engine/error.hpp"

namespace {

using tempera::cli::Args;

struct Command {
  const char* summary;
  std::function<int(const Args&)> run;
};

const std::map<std::string, Command>& commands() {
  static const std::map<std::string, Command> table = {
      {"synth", {"guided patch synthesis of one image (StyLit / image analogies)", tempera::cli::run_synth}},
      {"render-guides",
       {"render a .blend scene's guide cache with background Blender", tempera::cli::run_render_guides}},
      {"stylize", {"stylize an animation by example, with any method (--method; resumable)", tempera::cli::run_stylize}},
      {"noisy", {"add temporal noise to a coherent sequence (Color Me Noisy, resumable)", tempera::cli::run_noisy}},
  };
  return table;
}

// Commands that became another, named when a script still calls them.
const std::map<std::string, std::string>& moved_commands() {
  static const std::map<std::string, std::string> table = {
      {"rigid",
       "'tempera rigid' is now 'tempera stylize --method rigid --guides CACHE --frames A-B --out OUT' "
       "(--cache is --guides; the frames go to OUT/frames; see tempera stylize --method rigid --help)"},
  };
  return table;
}

void print_help() {
  std::cout << "usage: tempera [--help] [--version] <command> [options]\n\n"
               "Tempera stylizes 3D animations by example.\n\n";
  std::cout << "commands:\n";
  for (const auto& [name, command] : commands())
    std::cout << "  " << name << std::string(16 - std::min<size_t>(15, name.size()), ' ') << command.summary
              << "\n";
  std::cout << "\nRun 'tempera <command> --help' for a command's options.\n";
}

}  // namespace

int main(int argc, char** argv) {
  Args args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    print_help();
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "--version") {
    std::cout << "tempera " << TEMPERA_VERSION << "\n";
    return 0;
  }
  if (const auto moved = moved_commands().find(args[0]); moved != moved_commands().end()) {
    std::cerr << "tempera: " << moved->second << "\n";
    return 2;
  }
  auto it = commands().find(args[0]);
  if (it == commands().end()) {
    std::cerr << "tempera: unknown command '" << args[0] << "' (see tempera --help)\n";
    return 2;
  }
  try {
    return it->second.run(Args(args.begin() + 1, args.end()));
  } catch (const tempera::ValueError& e) {
    std::cerr << "tempera " << args[0] << ": error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "tempera " << args[0] << ": error: " << e.what() << "\n";
    return 1;
  }
}

// `tempera`: the batch command line. Runs the native solvers on files on disk,
// with no Blender and no Python, so a render farm can split work by frames.
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "cli_args.hpp"
#include "commands.hpp"
#include "tempera/engine/error.hpp"

namespace {

using tempera::cli::Args;
using tempera::cli::commands;

void print_help() {
  std::cout << "usage: tempera [--help] [--version] <command> [options]\n\n"
               "Tempera stylizes 3D animations by example.\n\n";
  std::cout << "commands:\n";
  for (const auto& [name, command] : commands())
    if (!command.summary.empty())
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

// `tempera`: the batch command line. Runs the native solvers on files on disk,
// with no Blender and no Python, so a render farm can split work by frames.
#include <cstring>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
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

// Images and feature planes are allocated and freed whole, a level or an
// input at a time. glibc maps allocations above its mmap threshold and
// unmaps them when freed, but raises that threshold to the size of each
// mapped block freed (up to 32 MB): after the first freed image every later
// one comes from the heap, whose freed pages stay resident, so the process
// held what the solve had freed. A fixed 1 MiB threshold hands every freed
// image back at once.
void return_freed_images_to_the_system() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
}

int main(int argc, char** argv) {
  return_freed_images_to_the_system();
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

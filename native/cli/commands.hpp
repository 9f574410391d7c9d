#pragma once
// The commands of `tempera`, by name: the core's own (synth, render-guides,
// stylize) and those a method's folder registers with its command file
// (native/src/methods/NAME/NAME_command.cpp, as it registers its binding),
// so that main.cpp and the core's headers name no method.
#include <functional>
#include <map>
#include <string>

#include "cli_args.hpp"

namespace tempera::cli {

struct Command {
  std::string summary;  // its line in `tempera --help`; "" for a command that moved (not listed)
  std::function<int(const Args&)> run;  // its exit status
};

// Every command by name (the method folders' are added before main runs).
std::map<std::string, Command>& commands();

// `const CommandRegistration kCommand("NAME", "summary", run_NAME);` at
// namespace scope in a method's command file adds it. tempera_commands is an
// object library, so that such a file is linked although nothing calls it.
struct CommandRegistration {
  CommandRegistration(const std::string& name, std::string summary, std::function<int(const Args&)> run);
};

}  // namespace tempera::cli

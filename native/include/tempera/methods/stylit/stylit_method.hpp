#pragma once
// StyLit's line of the method registry (methods/registry.hpp): its texts,
// unit and guide needs; it runs through its command (cli/stylize_command.cpp, shared with the coherent method).
#include "tempera/methods/registry.hpp"

namespace tempera {

MethodEntry stylit_method();

}  // namespace tempera

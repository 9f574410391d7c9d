#pragma once
// The coherent method's line of the method registry (methods/registry.hpp): its texts,
// unit and guide needs; it runs through StyLit's command (cli/stylize_command.cpp), by segments.
#include "tempera/methods/registry.hpp"

namespace tempera {

MethodEntry tcia_method();

}  // namespace tempera

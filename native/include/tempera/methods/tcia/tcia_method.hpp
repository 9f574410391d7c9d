#pragma once
// The coherent method's line of the method registry (methods/registry.hpp):
// its texts, unit, guide needs and own flags; it runs by segments through
// its command (cli/stylize_command.cpp), which also takes StyLit's options.
#include "tempera/methods/registry.hpp"

namespace tempera {

MethodEntry tcia_method();

}  // namespace tempera

#pragma once
// Fluidymation's line of the method registry (methods/registry.hpp): its
// texts, its options and its job factory, which `tempera stylize --method
// fluidymation` runs through the registry's one command.
#include "tempera/methods/registry.hpp"

namespace tempera {

MethodEntry fluidymation_method();

}  // namespace tempera

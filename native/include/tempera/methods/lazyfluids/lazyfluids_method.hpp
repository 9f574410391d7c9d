#pragma once
// LazyFluids' line of the method registry (methods/registry.hpp): its texts,
// its options and its job factory, which `tempera stylize --method
// lazyfluids` runs through the registry's one command.
#include "tempera/methods/registry.hpp"

namespace tempera {

MethodEntry lazyfluids_method();

}  // namespace tempera

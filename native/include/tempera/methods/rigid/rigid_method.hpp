#pragma once
// The rigid-body method's line of the method registry (methods/registry.hpp): its texts,
// unit and guide needs; it runs through the Python package (python_command).
#include "tempera/methods/registry.hpp"

namespace tempera {

MethodEntry rigid_method();

}  // namespace tempera

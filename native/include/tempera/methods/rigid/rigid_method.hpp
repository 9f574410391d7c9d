#pragma once
// The rigid-body method's line of the method registry (methods/registry.hpp): its texts,
// unit, options and its job (rigid_job.hpp).
#include "tempera/methods/registry.hpp"

namespace tempera {

MethodEntry rigid_method();

}  // namespace tempera

#pragma once
// Color Me Noisy's line of the method registry (methods/registry.hpp): the
// paper's 3D case as a method of its own, `tempera stylize --method noisy`:
// the shot's render (or coherent frames given) boiled with a medium's
// texture. The same pass also runs after a light-path method (--noise).
#include "tempera/methods/registry.hpp"

namespace tempera {

MethodEntry noisy_method();

}  // namespace tempera

#pragma once
// StyLit's line of the method registry (methods/registry.hpp): its texts,
// unit, guide needs, job factory and help (its options: --exemplar-guides,
// --exemplar-frame, --weights, --temporal, --quality and the engine's). The
// command line runs it through the registry's one command
// (cli/method_command.cpp), which adds a light-path method's exemplar scene,
// video and noise pass (cli/light_path_extras.hpp).
#include "tempera/methods/registry.hpp"

namespace tempera {

MethodEntry stylit_method();

}  // namespace tempera

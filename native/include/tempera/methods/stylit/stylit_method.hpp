#pragma once
// StyLit's line of the method registry (methods/registry.hpp): its texts,
// unit, guide needs and job factory (its options: --exemplar-guides,
// --exemplar-frame, --weights, --temporal, --quality and the engine's). The
// command line still runs it through its own command
// (cli/stylize_command.cpp, shared with the coherent method: the exemplar
// scene, the noise pass, the video).
#include "tempera/methods/registry.hpp"

namespace tempera {

MethodEntry stylit_method();

}  // namespace tempera

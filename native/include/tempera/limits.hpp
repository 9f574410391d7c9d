#pragma once
// Bounds on engine options that would otherwise let one value cost unbounded
// time or memory. Shared by the engine, the stylize job and the CLI.
#include "tempera/error.hpp"

namespace tempera {

// Pyramid levels: each halves the image, so 16 reach 1 pixel from 65536.
constexpr int kMaxPyramidLevels = 16;

inline void check_levels(int levels) {
  if (levels < 0 || levels > kMaxPyramidLevels)
    throw ValueError(concat("levels must be from 0 (automatic) to ", kMaxPyramidLevels, ", got ", levels));
}

}  // namespace tempera

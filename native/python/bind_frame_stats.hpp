#pragma once
// What a method's one-frame binding (StyLit's stylize_frame, LazyFluids'
// stylize_fluid_frame) reports besides the image: the same keys for every
// method, so that benches chain and compare frames alike.
#include <pybind11/stl.h>

#include "numpy_bridge.hpp"
#include "tempera/engine/offset_field.hpp"
#include "tempera/engine/synthesis.hpp"

namespace tempera::py_bridge {

inline py::dict frame_stats(const SynthesisResult& result) {
  py::dict stats;
  stats["seconds"] = result.seconds;
  stats["source_coverage"] = result.source_coverage;
  stats["guide_channels"] = result.guide_channels;
  // The finest level's energy after its last iteration (the solver's objective, for comparisons).
  stats["final_energy"] = result.levels.empty() || result.levels.back().energy.empty()
                              ? 0.0
                              : double(result.levels.back().energy.back());
  stats["levels"] = py::cast(result.levels);  // per level solved, coarsest first (LevelStats)
  // The final matches as source positions (H, W, 2): the next frame's `previous_field`.
  stats["field"] = to_numpy(field_positions(result.field));
  return stats;
}

}  // namespace tempera::py_bridge

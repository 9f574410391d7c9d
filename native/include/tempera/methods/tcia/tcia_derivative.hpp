#pragma once
// Eq. 10 of Bénard et al. 2013 (§4.1), the input time-derivative term: with
// keys, the synthesis should change the way the input changes,
//   g_∂in = χ |(I_t(x) - I_{t-1}(x - V(x))) - (S(C_t) - S(C_{t-1}))|²,
// which is |S(C_t) - T(x)|² with the target
//   T(x) = I_t(x) + (S(M_{t-1}) - I_{t-1})(x - V(x)):
// the frame's guides plus the previous frame's guide mismatch (the guides of
// the exemplar pixels it copies, less its own guides) carried along the
// motion. So g_∂in is one more guide pair per guide layer (source S, target
// T, weight map χ), recomputed per level and sweep like g_tc. Two readings
// of ours: C_{t-1}(p - V(p), Δp) is taken per window pixel at x - V(x) (the
// warp of the previous frame's S(M), as g_tc warps its output); and the
// targets are computed from full-size images picked to the level's size
// (the solver's own pyramid averages them; the two agree at the finest
// level). g_∂out, the same with Î and Ŝ, is left out: with output centre,
// Î_{t-1} = Ŝ(M_{t-1}) and the term only asks that the window's copies move
// together, which spatial coherence (eq. 5) already asks; the paper too
// found its influence "limited".
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/engine/offset_field.hpp"

namespace tempera {

class Solver;

// S(M): per pixel of the level field `field`, the guide of the exemplar
// pixel it copies. exemplar_guides[e] is the full-size guide of the solver's
// exemplar e (0 the style, k + 1 key k as padded), all of one layer.
Image matched_guide(const Solver& solver, int level, const OffsetField& field,
                    const std::vector<ImageView>& exemplar_guides);

// T above at level size: guide (I_t) + the previous frame's mismatch
// (previous_matched - previous_guide) warped along `velocity` (V- of this
// frame at the level, level pixels; minus V+ in backward sweeps).
Image derivative_target(const Image& guide, const Image& previous_guide, const Image& previous_matched,
                        const ImageView& velocity);

}  // namespace tempera

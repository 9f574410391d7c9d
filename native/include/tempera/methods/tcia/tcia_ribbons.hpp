#pragma once
// Ribbons (Bénard et al. 2013, §4.1): for every pixel of every frame, where
// its surface point lies in the keyframe before and the keyframe after,
// followed along the rendered motion (V- back to the previous key, V+ on to
// the next). A chain breaks where χ says the point is hidden in the next
// frame of the chain, or leaves the picture. The sweeps inject the two ends
// as PatchMatch candidates (the key's own pixel for that surface point), and
// propagation and random search then explore the key pixels' neighbours.
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/engine/patchmatch.hpp"

namespace tempera {

struct Shot;
class Solver;

// Per frame: the end of each pixel's ribbon in the previous and the next
// key (2 channels, key-frame pixels, sub-pixel), NaN where the chain breaks;
// and the index (into Shot::keys) of each key, -1 for none (and for both at
// a key frame, whose pixels are the key's own).
struct FrameRibbons {
  Image to_previous, to_next;
  int previous_key = -1, next_key = -1;
};

// The ribbons of every frame of the shot, in frame order.
std::vector<FrameRibbons> trace_ribbons(const Shot& shot);

// A frame's ribbon ends at `level` of `solver` as candidates (up to two per
// target pixel): key k is the solver's exemplar k + 1, its painting padded
// by `margin` pixels on each side.
CandidateList ribbon_candidates(const FrameRibbons& ribbons, const Solver& solver, int level, int margin);

}  // namespace tempera

#pragma once
// The neighbour sum of Bénard et al. 2013's spatial coherence (eq. 5) for an
// unrotated patch under a window, clipped to the field: the term's hot loop (it
// was most of the coherent method's time, one sum of 80 neighbours per
// candidate). Eight neighbours of a row at a time; the AVX2 kernel and the
// scalar one add the same products in the same order, so they agree to the bit.
#include <cstddef>
#include <cstdint>
#include <limits>

#include "tempera/engine/energy_term.hpp"     // PairCostBox
#include "tempera/engine/patch_distance.hpp"  // FixedKernel

namespace tempera {

struct CoherencePatch {
  const std::int32_t* x = nullptr;  // the field's matches, row-major, `pitch` per row
  const std::int32_t* y = nullptr;
  const std::uint8_t* matched = nullptr;  // 1 where a neighbour's match counts
  std::size_t pitch = 0;
  // The patch's rows and columns inside the field, [0, 2 radius] inclusive,
  // and the field index of its first pixel there (row0, col0).
  int row0 = 0, row1 = 0, col0 = 0, col1 = 0;
  std::size_t first = 0;
  const float* window = nullptr;  // (2 radius + 1)^2 weights, row-major
  int radius = 0;
  int source_x = 0, source_y = 0;  // the candidate's source centre
  float r_max2 = 0.0f;             // r_max^2: one neighbour's cap
};

// sum over the neighbours d != 0 with matched(p + d) of
// window(d) * min(|M(p + d) - (source + d)|^2, r_max^2), or infinity once
// the sum of the rows so far reaches `limit` (a rejected candidate: the rest
// cannot lower it). Kernel Best picks AVX2 where the CPU has it, else Scalar.
float coherence_patch_sum(const CoherencePatch& patch, float limit = std::numeric_limits<float>::infinity(),
                          FixedKernel kernel = FixedKernel::Best);

// The sources a counted neighbour's match reaches: neighbour p + d matched to
// M implies the source M - d for p; within r_max of one of those, its term
// is below the cap. The box holds them all, widened by r_max; for any source
// outside it every neighbour is capped, and coherence_patch_sum() is
// `outside` to the bit (the same products added in the same order), so most
// random-search candidates need no sum. `patch.source_x/y` are not read.
PairCostBox coherence_reach(const CoherencePatch& patch);

// What coherence_reach_row() reads: the field at the start of the sweep.
struct CoherenceField {
  const std::int32_t* x = nullptr;  // matches, row-major, `width` per row
  const std::int32_t* y = nullptr;
  const std::uint8_t* matched = nullptr;
  int width = 0, height = 0;
  const float* window = nullptr;  // (2 radius + 1)^2 weights
  int radius = 0;
  float r_max2 = 0.0f;
};

// coherence_reach() of every target of row ty (boxes[tx]), at a few
// operations a target: from minima and maxima of the matches' offsets
// M(n) - n, per column of the window's rows and then over its columns. A
// box may be wider than coherence_reach()'s (it counts the target's own
// match too), never narrower, so a source outside it is outside that one
// too; `outside` is the same to the bit. Targets whose window is clipped by
// the field or holds an unmatched pixel take coherence_reach() itself.
void coherence_reach_row(const CoherenceField& field, int ty, PairCostBox* boxes);

}  // namespace tempera

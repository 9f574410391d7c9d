#pragma once
// Converged pixels: the forward search skips them in the next EM iteration.
// A target pixel whose match, whose four neighbours' matches (what
// propagation offers it) and whose patch of B' (what its distances are
// measured against) all came out of an EM iteration unchanged faces the same
// search problem in the next iteration as in this one, which already found
// nothing better: searching it again only draws new random candidates, which
// at the fine levels almost never win (docs/benchmarks.md, issue 11). In the
// spirit of ebsynth's stop threshold. A pixel that the error budget's
// reversed retrieval reassigned has a new match, so it is not converged.
// Skipped pixels keep their match and still propagate it to their neighbours.
#include <cstdint>
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/engine/offset_field.hpp"

namespace tempera {

// A B' value that moved by less than this (in the style's units, one 8-bit
// step) counts as unchanged.
constexpr float kConvergedChange = 1.0f / 255.0f;

// One number per target pixel that changes whenever its match (position and
// remainder) changes; equal numbers mean an unchanged match (a collision,
// 2^-32 per pixel, at worst skips one pixel's search once).
std::vector<std::uint32_t> match_fingerprints(const OffsetField& field);
// The same into `out` (its buffer reused: the EM loop takes them each iteration).
void match_fingerprints(const OffsetField& field, std::vector<std::uint32_t>& out);
std::uint32_t match_fingerprint(const OffsetField& field, std::size_t i);

// Per pixel: some channel of `after` differs from `before` by kConvergedChange or more.
std::vector<std::uint8_t> changed_pixels(const ImageView& before, const ImageView& after);

// Sets moved[i] where the match of pixel i differs from `before`. Called
// after the search and again after the error budget's reassignment, so that a
// match the search changed and the budget put back still counts as moved.
void mark_moved(const OffsetField& field, const std::vector<std::uint32_t>& before, std::vector<std::uint8_t>& moved);

// Per target pixel of a w x h frame: 1 = search it in the next iteration. A
// pixel is searched if it is active and its match or a 4-neighbour's moved,
// or a pixel of its patch (side 2 radius + 1) changed in B'.
std::vector<std::uint8_t> pixels_to_search(int w, int h, const std::vector<std::uint8_t>& moved,
                                           const std::vector<std::uint8_t>& image_changed, int radius,
                                           const std::vector<std::uint8_t>& active);

}  // namespace tempera

#pragma once
// Rigid moving-least-squares deformation (Schaefer et al. 2006, §2.3), as
// Color Me Noisy pre-deforms its exemplar every frame (Fišer et al. 2014,
// §3.2): a lattice of control points moved at random, and the image warped so
// that it follows them as rigidly as it can.
#include <cstdint>
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

struct Point2 {
  float x = 0, y = 0;
};

// The rigid MLS map of control points p -> q evaluated at v (weights
// 1 / |p_i - v|^2). It interpolates: v = p_i gives q_i.
Point2 rigid_mls(const std::vector<Point2>& p, const std::vector<Point2>& q, Point2 v);

// A lattice over width x height with nodes about every `spacing` pixels (at
// least 2 x 2, corners included), each moved by a length in [shift_min,
// shift_max] in a random direction that turns smoothly from node to node
// (see mls.cpp for why); deterministic in `seed`.
struct MlsLattice {
  std::vector<Point2> rest, moved;
};
MlsLattice random_lattice(int width, int height, float spacing, float shift_min, float shift_max,
                          std::uint64_t seed);

// For each output pixel, the position in `image` it samples: the rigid MLS map
// from the moved lattice back to the rest lattice, so the output shows the
// image with its lattice nodes carried to their moved places. (W x H x 2)
Image mls_backward_map(const MlsLattice& lattice, int width, int height);

// `image` sampled at `map` (bilinear, clamped at the border); with
// `nearest`, nearest-pixel (labels, masks as they are).
Image warp_by_map(const ImageView& image, const ImageView& map, bool nearest = false);

}  // namespace tempera

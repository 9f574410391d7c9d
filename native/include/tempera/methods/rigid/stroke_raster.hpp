#pragma once
// Anti-aliased drawing of polylines and polygons into 1-channel coverage
// images: the proxy silhouettes and the generated "hand-drawn" strokes of
// the rigid-body method, and its tests' synthetic exemplars.
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/methods/rigid/quadratic_map.hpp"

namespace tempera {

// A stroke of the given width (px) along `points` (pixel (x, y) has its
// centre at (x, y)): coverage clamp(width / 2 + 0.5 - distance, 0, 1),
// merged into `ink` (1 channel) by max.
void draw_stroke(Image& ink, const std::vector<Vec2>& points, double width, bool closed);

// The polygon's area coverage, 4 x 4 supersampled, merged by max.
void fill_polygon(Image& mask, const std::vector<Vec2>& polygon);

}  // namespace tempera

#pragma once
// Filled silhouettes of line drawings and the shape metrics of the
// rigid-body method: the drawing's outline is closed into a region the
// quadratic registration can align, and outputs are compared to exemplars
// by symmetric chamfer distance and IoU.
#include <vector>

#include "tempera/engine/gaussian_blur.hpp"
#include "tempera/engine/image.hpp"
#include "tempera/methods/rigid/quadratic_map.hpp"

namespace tempera {

// A soft silhouette of a drawing (1 channel ink coverage): 1 inside the
// closed outline (pixels the background flood fill from the border does not
// reach), 0 outside, and half the ink's coverage on the strokes, so that the
// 0.5 level of the blurred silhouette runs along the strokes' middle, not
// their outer edge.
Image filled_silhouette(const ImageView& ink, float threshold = 0.5f);

// Sub-pixel points where channel 0 crosses `level` between 4-neighbours.
std::vector<Vec2> iso_points(const ImageView& image, float level = 0.5f);

// Symmetric chamfer distance (px) between two drawings: the mean, over the
// ink pixels (> 0.5) of each, of the distance to the other's nearest ink
// pixel, averaged over both directions. Throws when either has no ink.
double chamfer_distance(const ImageView& a, const ImageView& b);

// Intersection over union of two masks thresholded at 0.5.
double iou(const ImageView& a, const ImageView& b);

}  // namespace tempera

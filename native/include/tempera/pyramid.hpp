#pragma once
// Image pyramids for coarse-to-fine synthesis (factor 2 per level).
#include <vector>

#include "tempera/image.hpp"

namespace tempera {

// Half-size image by 2x2 box filtering (odd edges take the last row/column).
Image downsample_half(const ImageView& image);

// Level 0 is the full-resolution image; each next level is half the size.
std::vector<Image> build_pyramid(const ImageView& image, int levels);

// Number of levels so that the smallest side at the coarsest level stays at
// least `min_side` pixels (and at most `max_levels`).
int pyramid_levels_for(int width, int height, int min_side, int max_levels = 12);

}  // namespace tempera

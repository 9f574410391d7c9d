#pragma once
// Image pyramids for coarse-to-fine synthesis: factor 2 per level by 2x2 box
// averaging (the default), or any ratio by area resampling with an optional
// box low-pass per level (Color Me Noisy's 0.85 pyramid with filter widths).
#include <utility>
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

// Half-size image by 2x2 box filtering (odd edges take the last row/column).
Image downsample_half(const ImageView& image);

// Number of levels so that the smallest side at the coarsest level stays at
// least `min_side` pixels (and at most `max_levels`), at `ratio` per level.
int pyramid_levels_for(int width, int height, int min_side, int max_levels = 12, double ratio = 0.5);

// (width, height) of each level, finest first: halving rounds up (as
// downsample_half does); other ratios round to nearest, at least 1.
std::vector<std::pair<int, int>> level_sizes(int width, int height, int levels, double ratio);

// `image` resampled to width x height by exact area averaging (each output
// pixel is the mean of the input area it covers).
Image resize_area(const ImageView& image, int width, int height);

// Box low-pass of width `width` pixels (fractional widths weigh the edge
// pixels by the remainder), clamped at the borders. width <= 1: a copy.
Image box_blur(const ImageView& image, float width);

// Level 0 is the full-resolution image, each next level `ratio` of the
// previous' size: at 0.5 each is the previous halved (downsample_half);
// other ratios resample level 0 to each level's size. box_widths (finest
// first, may be shorter) low-pass each level after resampling.
std::vector<Image> build_pyramid(const ImageView& image, int levels, double ratio,
                                 const std::vector<float>& box_widths);
// The same, level 0 being `image` itself (moved in, not copied: the solver's
// stacked exemplar and target guides are the largest images it builds).
std::vector<Image> build_pyramid(Image&& image, int levels, double ratio, const std::vector<float>& box_widths);

}  // namespace tempera

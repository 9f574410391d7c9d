#pragma once
// Bounded distance to lines, the guide D(I) of Bénard et al. 2013's distance
// transform term (§3.2): far from any line the guide saturates so that
// synthesis there falls back to the other goals.
#include <string_view>

#include "tempera/engine/image.hpp"

namespace tempera {

// Exact Euclidean distance from each pixel centre to the nearest line pixel
// of a 1-channel mask (value > 0.5 = line), by Felzenszwalb & Huttenlocher's
// separable lower-envelope algorithm (2012), returned as
// min(distance, d_max) / d_max in [0, 1]: 0 on lines, 1 at d_max and beyond.
// A mask without line pixels gives all 1.
Image line_distance(const ImageView& mask, float d_max = 10.0f);

// The unbounded distance from each pixel centre to the nearest pixel with
// mask > 0.5 (0 on them); +inf everywhere if there is none. Same algorithm.
Image euclidean_distance(const ImageView& mask, std::string_view what = "mask");

// The nearest pixel with mask > 0.5 of each pixel (the argmin of
// euclidean_distance; itself on the mask), as 2 channels (x, y); (-1, -1)
// everywhere if there is none. Ties go to one of the nearest, always the same.
Image nearest_mask_pixel(const ImageView& mask, std::string_view what = "mask");

}  // namespace tempera

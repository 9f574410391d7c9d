#pragma once
// Signed distance to a mask's boundary (Platkevič et al. 2021, App. A, on
// Felzenszwalb & Huttenlocher's exact transform, distance_transform.hpp):
// positive inside, negative outside, about 0 on the boundary (half a pixel
// either side of it), in pixels.
#include "tempera/engine/image.hpp"

namespace tempera {

// 1 channel: the distance from each inside pixel (mask > 0.5) to the nearest
// outside pixel minus 1/2, and minus the same the other way round outside. A
// mask with no inside (or no outside) pixel saturates at -/+ the image
// diagonal, so the field stays finite.
Image signed_distance(const ImageView& mask);

// 2 channels: the central-difference gradient (d/dx, d/dy) of a 1-channel
// field (one-sided at the image border). For a signed distance it points
// inward, towards larger values.
Image gradient(const ImageView& field);

}  // namespace tempera

#pragma once
// Separable Gaussian blur: the smoothing shared by the silhouette metrics,
// the quadratic registration and the blurred-alpha guides of LazyFluids and
// Fluidymation (alpha_segments.hpp).
#include "tempera/engine/image.hpp"

namespace tempera {

// Every channel blurred by a Gaussian of standard deviation `sigma` pixels
// (taps out to 3 sigma), pixels beyond the border replaced by the nearest edge
// pixel. sigma <= 0 returns a copy. Deterministic (a fixed summation order).
Image gaussian_blur(const ImageView& image, float sigma);

}  // namespace tempera

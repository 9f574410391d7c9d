#pragma once
// Colour conversions for matching in a perceptual space.
#include "tempera/engine/image.hpp"

namespace tempera {

// sRGB-encoded RGB in [0, 1] (the first three channels; others are copied)
// to CIE L*a*b* (D65) divided by 100, so L* spans [0, 1] like the input and
// distances keep their scale against the guides.
Image srgb_to_lab(const ImageView& rgb);

}  // namespace tempera

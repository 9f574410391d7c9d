#pragma once
// Colour conversions for matching in a perceptual space.
#include "tempera/engine/image.hpp"

namespace tempera {

// sRGB-encoded RGB in [0, 1] (the first three channels; others are copied)
// to CIE L*a*b* (D65) divided by 100, so L* spans [0, 1] like the input and
// distances keep their scale against the guides.
Image srgb_to_lab(const ImageView& rgb);

// Linear Rec.709 values (the first three channels; others are copied) to
// sRGB-encoded values in [0, 1] (IEC 61966-2-1), clipped first as Blender's
// Standard view shows them (no tone mapping); NaN becomes 0. A render as an
// 8-bit PNG would hold it (tempera.engine.color.linear_to_srgb in Python).
Image linear_to_srgb(const ImageView& linear);

}  // namespace tempera

#pragma once
// Orientation fields O(I) of Bénard et al. 2013 (§3.1), computed as the
// per-pixel structure tensor of the grayscale image (Granlund & Knutsson
// 1995). The tensor, not the angle, is what gets interpolated or averaged:
// angles wrap at π, tensors add up linearly.
//
// Conventions: x to the right, y down (image rows). An angle a stands for
// the direction (cos a, sin a) in those coordinates, and is the *edge*
// direction: along stripes, perpendicular to the intensity gradient.
#include "tempera/engine/image.hpp"

namespace tempera {

// 3 channels per pixel: (Jxx, Jxy, Jyy) = Gaussian-smoothed (gx², gx·gy, gy²).
using StructureTensorField = Image;

// Structure tensor of `gray`: the mean of the first 3 channels (or the only
// one) is differentiated with Sobel filters, and the tensor components are
// smoothed with a separable Gaussian of standard deviation `sigma` pixels
// (0: no smoothing, at most kMaxStructureTensorSigma, else ValueError). Borders
// replicate the edge pixels; the kernel is clamped to the image (exactly: the
// taps beyond it all read the edge pixel), so a huge sigma costs no more
// than one as wide as the image.
constexpr float kMaxStructureTensorSigma = 1000.0f;
StructureTensorField structure_tensor(const ImageView& gray, float sigma = 2.0f);

// (angle, coherence) per pixel from a 3-channel tensor: angle in [0, π) of
// the dominant edge direction, coherence (λ1 - λ2) / (λ1 + λ2) in [0, 1]
// (0: flat or isotropic, 1: a single clean orientation). A zero tensor gives
// coherence 0 and angle π/2 (a finite, arbitrary value).
Image orientation_from_tensor(const ImageView& tensor);

}  // namespace tempera

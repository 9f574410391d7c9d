#pragma once
// Motion building blocks of Bénard et al. 2013 (§3.1): occlusion tests from
// rendered velocity fields, and backward advection of a previous frame.
//
// Conventions. Velocities are 2-channel float images (x, y) in pixels, with
// x to the right and y down (image rows), and pixel (x, y) centred on the
// integer position (x, y).
//   V+_t(p): a point visible at p in frame t moves to p + V+_t(p) in frame t+1.
//   V-_t(p): a point visible at p in frame t came from p - V-_t(p) in frame t-1.
// So both fields hold the displacement *from the earlier frame to the later*
// one, and along a consistent motion path V-_t(p) = V+_{t-1}(p - V-_t(p)):
// the paper's round trip (p - V-) + V+_{t-1}(p - V-) = p. That is why χ
// compares the two fields by their *difference* (≈ 0 -> visible, χ = 1).
#include "tempera/engine/image.hpp"

namespace tempera {

// χ-(p, t) = 1 if ||V+_{t-1}(p - V-_t(p)) - V-_t(p)||² < epsilon, else 0:
// 1 where p was visible in frame t-1, 0 where it has just been disoccluded.
// V+_{t-1} is sampled bilinearly; a point coming from outside the frame
// (beyond the outer half pixel) gets 0. Returns a 1-channel image of 0/1.
Image occlusion_backward(const ImageView& v_minus_t, const ImageView& v_plus_prev, float epsilon = 2.0f);

// χ+(p, t) = 1 if ||V-_{t+1}(p + V+_t(p)) - V+_t(p)||² < epsilon, else 0:
// 1 where p stays visible in frame t+1, 0 where it is about to be occluded
// (or leaves the frame).
Image occlusion_forward(const ImageView& v_plus_t, const ImageView& v_minus_next, float epsilon = 2.0f);

// The previous frame advected to frame t: out(p) = previous(p - V-_t(p)),
// sampled bilinearly with positions clamped to the frame. Any channel count.
// Disoccluded pixels get whatever was there before; mask them with χ-.
Image warp_backward(const ImageView& previous, const ImageView& v_minus_t);

}  // namespace tempera

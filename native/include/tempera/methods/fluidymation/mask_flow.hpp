#pragma once
// Flow of a mask sequence (Platkevič et al. 2021, App. A), for an exemplar
// or target given as masks only. Per frame:
//  - on the mask's boundary the flow is normal to it, with the speed at which
//    the signed distance (signed_distance.hpp, positive inside) changes:
//    F_i = -(dist_{i+1} - dist_i) grad(dist_i) / |grad(dist_i)|. The minus
//    is the level-set equation's (phi_t + v . grad(phi) = 0) and is what makes
//    an expanding disc flow outward; App. A prints it without, as the
//    backward difference of the frame before, which flips the direction;
//  - the interior is filled by diffusing the boundary values (Johnston 2002:
//    a harmonic fill, Laplace's equation with the boundary held);
//  - the distance fields are first smoothed by a temporal Gaussian of
//    `temporal_radius` frames (sigma = radius / 2): the paper's Fig. 14
//    smooths the distance fields, which gives sub-pixel speeds and, unlike
//    smoothing the flows, does not mix a boundary pixel's speed with the
//    slower interior it becomes in later frames.
// Convention: pixels per frame, x right, y down, forward (p moves to p + F in
// the next frame), like the guide cache's velocity_forward. 0 outside the
// mask. The last frame, which has no next one, takes its predecessor's
// boundary speeds.
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

// One 2-channel flow per mask (1 channel, > 0.5 = inside, all the same size;
// at least 2 masks).
std::vector<Image> flow_from_masks(const std::vector<ImageView>& masks, float temporal_radius = 3.0f);

// The harmonic fill of `values` (2 channels) inside `mask`: pixels where
// `known` > 0.5 keep their values, the other inside pixels solve Laplace's
// equation (a push-pull first guess, then red-black over-relaxation); 0
// outside.
Image diffuse_fill(const ImageView& values, const ImageView& known, const ImageView& mask);

}  // namespace tempera

#pragma once
// Frame-by-frame stylization of the rigid-body method (Dvorožňák et al.
// 2017, §6): the residual f^r = D^-1(f^e) of each drawn frame, carried to the
// target pose, deformed by the blended D_hat and merged across the K matches;
// then the contact fix that puts the drawing on the obstacle at events.
#include <functional>
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/methods/rigid/quadratic_fit.hpp"
#include "tempera/methods/rigid/rigid.hpp"

namespace tempera {

// f^r(p) = f^e(frame(D(u(p)))): the drawing with D undone, a backward warp
// (no inverse needed). Any channel count; bilinear.
Image extract_residual(const ImageView& drawing, const QuadraticMap& D, ObjectFrame frame);

// f^e again from the residual: out(p) = f^r(frame(D^-1(u(p)))), the inverse
// by Newton steps; pixels D does not reach stay 0.
Image apply_map(const ImageView& residual, const QuadraticMap& D, ObjectFrame frame);

// The residual of exemplar `e`, frame `f` (RGBA, straight alpha).
using ResidualSource = std::function<ImageView(int exemplar, int frame)>;

// One target frame (RGBA, width x height): every matched residual moved
// rigidly to the target pose (centre, rotation theta^T - theta^S, radius
// ratio, the augmentation's flip and rotation), deformed by D_hat, and
// merged. `shift` moves the result (the contact fix). The merge, a
// documented stand-in for the n-way morph: the weighted mean of the warped
// strokes' distance fields, inked where it is below 1 px (alpha = 1 - mean
// distance), coloured by the weighted mean ink colour; one match is copied
// as it is.
Image render_rigid_frame(const std::vector<RigidExemplar>& exemplars, const ResidualSource& residuals,
                         const Track& target, int frame, const RigidFrame& deformation, int width, int height,
                         Vec2 shift = {});

// Signed gap (px) along the event's normal between the drawing (alpha) and
// the obstacle's tangent line through the contact point: > 0 a gap,
// < 0 a penetration.
double contact_gap(const ImageView& rgba, const RigidEvent& event);

// Per target frame, the contact fix: at each event the shift along the
// normal that closes the gap, faded linearly to 0 over `fade` frames on
// either side (overlapping fades add).
std::vector<Vec2> contact_shifts(const std::vector<RigidExemplar>& exemplars, const ResidualSource& residuals,
                                 const Track& target, const std::vector<RigidFrame>& deformations, int width,
                                 int height, int fade);

}  // namespace tempera

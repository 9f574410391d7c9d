#pragma once
// Example-based expressive animation of 2D rigid bodies (Dvorožňák et al.
// 2017) as a method: drawn exemplars F^E over source simulations F^S carry
// their squash, stretch, bend and line onto a target simulation F^T.
//
//  - every sequence is cut into overlapping sub-sequences around its events
//    (§4); each runs between the midpoints to the neighbouring events,
//    widened by M/2 on each side with M = min(8, gap / 4) [design];
//  - source and target sub-sequences are compared by Diff (eq. 3-6): the
//    velocity, trajectory direction and rotation terms, frames paired by
//    their signed offset from the event and averaged over the common frames
//    [design: the paper resamples by arc length and sums];
//  - the sources are augmented by rotations gamma (those that turn a source
//    event's normal onto the target's), 5 scales rho in [0.2, 1] (scaling the
//    source's speeds; D is radius-normalized, so it is unchanged) and a flip
//    about the vertical axis; D is conjugated, D_L(p) = L D(L^-1 p);
//  - the K nearest are blended rotation-aware (eq. 7-9) with w_k ~ 1/Diff,
//    damped by xi = clamp(sum |v^S| / sum |v^T|, 0, 1) (eq. 10, clamped
//    [design]) and kept unfolded by the fold guard [design];
//  - overlapping sub-sequences are blended with a linear ramp [design].
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/methods/rigid/quadratic_map.hpp"

namespace tempera {

// One object in one frame, as the simulation gives it (px, radians,
// image axes: x right, y down).
struct TrackFrame {
  Vec2 centre;
  Vec2 velocity;       // px per frame
  double theta = 0;    // the object's rotation
  double radius = 1;   // the proxy's screen radius
  double delta = 0;    // trajectory direction atan2(v)
  double alpha = 0;    // rotation relative to the trajectory, theta - delta
};

// A collision event: the frame, the contact point and the obstacle's normal
// (unit, pointing from the obstacle into the body).
struct RigidEvent {
  int frame = 0;
  Vec2 contact;
  Vec2 normal{0, -1};
};

struct Track {
  std::vector<TrackFrame> frames;
  std::vector<RigidEvent> events;  // sorted by frame
};

struct SubSequence {
  int event = -1;  // index into Track::events, -1 when the track has none
  int centre = 0;  // the key frame (the event's frame)
  // Inclusive. A match takes D from its frame at the same offset from the
  // event; past the ends, from the end frame faded to the identity over 2
  // frames [design], so that a short source never lends its neighbouring
  // event's squash to a long flight.
  int first = 0, last = 0;
};

// An augmentation of a source sub-sequence: p -> R_gamma F p, F the flip
// about the vertical axis, speeds times rho.
struct Augmentation {
  double gamma = 0;
  double rho = 1;
  bool flip = false;
};
// R_gamma F as a 2 x 2 row-major matrix.
std::array<double, 4> augmentation_matrix(const Augmentation& a);

struct RigidOptions {
  int k = 3;                  // K nearest source sub-sequences
  float lambda_vel = 0;       // 0 = 1 / (median target speed)^2
  float lambda_dir = 1;
  float lambda_rot = 1;
  int symmetry = 0;           // order n of rotational symmetry; 0 = a circle (lambda_rot = 0)
  bool augment = true;        // rotations, scales and flips of the sources
  int scales = 5;             // rho in [0.2, 1]
  bool flip = true;
  bool damp = true;
  float fold_min_det = 0.05f; // least det J the fold guard allows
  int contact_fade = 3;       // frames over which the contact fix fades out
  bool overlap_blend = true;  // ramp across sub-sequence overlaps; false: a hard cut at their middle
  // Stroke re-synthesis (§6 (iv), tempera.methods.rigid.rigid_strokes, when a stroke
  // exemplar is given): the stroke-position guide G = 1 - distance / d_max.
  float stroke_d_max = 4;     // px
  float stroke_weight = 4;    // the guide's weight in the engine's patch distance
};

inline const auto& rigid_option_table() {
  using R = RigidOptions;
  static const auto table = std::make_tuple(
      field(&R::k, "k", "k", "K nearest source sub-sequences blended per target sub-sequence (3)", 1, 64),
      field(&R::lambda_vel, "lambda_vel", "lambda-vel",
            "weight of the velocity term of Diff, per (px/frame)^2; 0 = 1 / (median target speed)^2", 0, 1e9),
      field(&R::lambda_dir, "lambda_dir", "lambda-dir", "weight of the trajectory-direction term of Diff (1)", 0, 1e9),
      field(&R::lambda_rot, "lambda_rot", "lambda-rot", "weight of the rotation term of Diff (1; unused for circles)",
            0, 1e9),
      field(&R::symmetry, "symmetry", "symmetry",
            "order of the objects' rotational symmetry (4 for a square); 0 = a circle, rotation ignored", 0, 360),
      field(&R::augment, "augment", "augment", "augment the sources by rotations, scales and flips"),
      field(&R::scales, "scales", "scales", "number of augmentation scales rho in [0.2, 1] (5)", 1, 32),
      field(&R::flip, "flip", "flip", "augment by a flip about the vertical axis (gravity stays down)"),
      field(&R::damp, "damp", "damp", "damp the blended deformation by the speed ratio xi (eq. 10)"),
      field(&R::fold_min_det, "fold_min_det", "fold-min-det",
            "least Jacobian determinant the fold guard allows over the object's disc (0.05)", 0, 1),
      field(&R::contact_fade, "contact_fade", "contact-fade",
            "frames over which the contact fix fades out around an event (3)", 0, 100),
      field(&R::overlap_blend, "overlap_blend", "overlap-blend",
            "blend overlapping sub-sequences with a linear ramp (off: a hard cut at the overlap's middle)"),
      field(&R::stroke_d_max, "stroke_d_max", "stroke-d-max",
            "stroke re-synthesis: reach in px of the stroke-position guide 1 - distance / d_max (4)", 0.5, 64),
      field(&R::stroke_weight, "stroke_weight", "stroke-weight",
            "stroke re-synthesis: weight of the stroke-position guide; 0 = unguided texture (4)", 0, 1e3));
  return table;
}

// Fills delta and alpha from velocity and theta; frames at rest keep the
// last direction.
void derive_trajectory_angles(Track& track, double rest_speed = 1e-3);

// Screen positions, speeds and radii of a real shot stay far below this (px);
// beyond it, like NaN and inf, they only make blank frames.
constexpr double kMaxTrackPixels = 1e6;
// ValueError naming the first frame or event whose values are not finite, out
// of kMaxTrackPixels (radius: not in (0, kMaxTrackPixels]) or an event frame
// outside the track; tracks.json is user input.
void validate_track(const Track& track);

// The sub-sequences of a track of `frame_count` frames.
std::vector<SubSequence> cut_subsequences(const Track& track);

// The smallest difference between two angles, modulo 2 pi / order (order
// 1 = an ordinary angle).
double angle_difference(double a, double b, int order = 1);

// The track seen through an augmentation (velocities, angles; the centres
// are kept, since D is relative to them).
TrackFrame augmented(const TrackFrame& f, const Augmentation& a);

// Diff(F^S_i, F^T_j) with weights from `options` (lambda_vel resolved).
double sub_sequence_diff(const Track& source, const SubSequence& s, const Augmentation& a, const Track& target,
                         const SubSequence& t, const RigidOptions& options, double lambda_vel);

// A source exemplar: its track and one fitted D per frame.
struct RigidExemplar {
  Track track;
  std::vector<QuadraticMap> maps;
};

// A matched residual frame for one target frame.
struct ResidualRef {
  int exemplar = 0;
  int frame = 0;
  Augmentation augmentation;
  double weight = 0;
};

struct RigidFrame {
  QuadraticMap D;                       // D_hat, radius-normalized at the target's centre
  std::vector<ResidualRef> residuals;   // their weights sum to 1
  double xi = 1;                        // the damping applied
};

// D_hat and the matched residuals for every target frame.
std::vector<RigidFrame> synthesize_deformations(const std::vector<RigidExemplar>& exemplars, const Track& target,
                                                const RigidOptions& options);

}  // namespace tempera

#pragma once
// Fluidymation (Platkevič et al. 2021) as a method on the engine: a target
// sequence of masks (and optionally flows) stylized by a video exemplar of a
// natural medium (ink, watercolour) with its masks, frame by frame. Each
// frame minimizes
//   D_tex + w_b D_bound + w_d D_dir + w_e D_ext + w_t m D_temp + w_u Omega
// over matches (i, x, y, theta) into the whole exemplar video (the engine's
// source set of video frames):
//  - D_bound: the shape guide, Gauss(mask, b), on both sides;
//  - D_ext: the motion extents ext+/ext- (motion_extent.hpp) as a guide;
//  - theta is not searched: source and target orientations are the flow
//    angles, and the engine rotates each patch by a_src - a_tgt, so the
//    rotated exemplar flow points along the target flow at the patch centre;
//    D_dir (a pair term) adds |tan| of what is left on the patch's corners
//    and edge midpoints;
//  - D_temp: the previous frame's field advanced in exemplar time by
//    SHIFTNNF (shift_nnf below) and voted, weighted by w_t m(q);
//  - Omega: footprint usage over the n x n x (2r + 1) cuboid
//    (make_footprint_usage with a temporal radius).
// Multi-scale: frame 1 starts cold at the coarsest level; later frames start
// there from DOWNSCALE(NNF_prev), and every finer level from UPSCALE of the
// coarser field with DOWNSCALE(NNF_prev) as a per-pixel candidate, so that
// PatchMatch keeps whichever has the lower D (MERGENNF).
//
// Choices where the paper is silent (docs/fluidymation.md):
//  - orientations are directed (axial_orientation = false) and taken from the
//    *expansion-signed* flow sigma * F, sigma = +1 where the flow leaves the
//    mask (the material spreads) and -1 where it enters (it recedes); the
//    motion extents are stored in the same expansion frame (ext+ and ext-
//    swapped where sigma = -1). So a receding target matched to a spreading
//    exemplar keeps the exemplar's fronts facing outward, D_ext compares
//    like with like with no per-pair swap, and SHIFTNNF plays such matches
//    backward (delta i <= 0 on ext-): the paper's "opposite flows";
//  - D_dir is clamped at |tan| = 1 and averaged over the patch's corners and
//    edge midpoints, so w_d = 1 weighs a fully misaligned patch like a unit
//    colour difference;
//  - ext is divided by `extent_scale` pixels before it is matched;
//  - the shape blur b is the Gaussian's radius, sigma = b / 3;
//  - m(q): smoothstep(|T_dist - S_dist|; m_l, m_u) as printed, or 1 - that
//    ("release", the default: a pixel whose exemplar lags far behind the
//    target's boundary is released from the temporal term; as printed the
//    term is off wherever the match keeps pace, and flickers more: tested);
//  - SHIFTNNF's exemplar time is fractional (quarter-frame search, kept while
//    a pixel keeps its match), so slower targets advance by fractions;
//  - DOWNSCALE picks the match under each level pixel's centre.
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/engine/synthesis.hpp"

namespace tempera {

// How SHIFTNNF picks delta i: by motion extent (the paper), or always +1
// (the baseline that cannot keep up with fast targets).
enum class TimeShift { Extent, One };
template <>
struct EnumNames<TimeShift> {
  static constexpr const char* what = "time shift";
  static constexpr std::array<const char*, 2> names = {"extent", "one"};
};

// Which way m(q) weighs the temporal term (see above).
enum class TemporalModulation { Release, Printed };
template <>
struct EnumNames<TemporalModulation> {
  static constexpr const char* what = "temporal modulation";
  static constexpr std::array<const char*, 2> names = {"release", "printed"};
};

struct FluidymationOptions {
  float boundary_weight = 4.0f;    // w_bound
  float shape_blur = 30.0f;        // b, pixels
  float extent_weight = 0.25f;     // w_ext
  float extent_scale = 10.0f;      // pixels of ext per guide unit
  float direction_weight = 1.0f;   // w_dir
  float temporal_weight = 4.0f;    // w_temp
  float uniformity_weight = 1.0f;  // w_uni
  int uniformity_frames = 5;       // r
  float modulation_lower = 0.01f;  // m_l as a fraction of d, the target's larger side
  float modulation_upper = 0.1f;   // m_u
  TemporalModulation modulation = TemporalModulation::Release;
  TimeShift time_shift = TimeShift::Extent;
  bool rotate = true;              // orientations from the flow (off: axis-aligned patches)
  float flow_smoothing = 3.0f;     // temporal radius of flows from masks (App. A)
  bool bidirectional = false;      // forward and backward passes merged
  SynthesisOptions synthesis;      // fluidymation_defaults()
};

inline const auto& fluidymation_option_table() {
  using F = FluidymationOptions;
  static const auto table = std::make_tuple(
      field(&F::boundary_weight, "boundary_weight", "boundary-weight",
            "w_bound: match the blurred mask shape, so edges look like the exemplar's edges (4)", 0, 1e6),
      field(&F::shape_blur, "shape_blur", "shape-blur", "b: radius in pixels of the mask blur of the shape guide (30)",
            0.5, 1000),
      field(&F::extent_weight, "extent_weight", "extent-weight",
            "w_ext: match the motion extent ext+/ext-, moving paint from moving exemplar parts (0.25)", 0, 1e6),
      field(&F::extent_scale, "extent_scale", "extent-scale", "pixels of motion extent per guide unit (10)", 0.01,
            1e6),
      field(&F::direction_weight, "direction_weight", "direction-weight",
            "w_dir: keep the rotated exemplar flow along the target flow across the patch (1)", 0, 1e6),
      field(&F::temporal_weight, "temporal_weight", "temporal-weight",
            "w_temp: pull towards the previous frame advanced in exemplar time (4)", 0, 1e6),
      field(&F::uniformity_weight, "uniformity_weight", "uniformity-weight",
            "w_uni: spread the use of exemplar patches (footprint coverage), against wash-out (1)", 0, 1e6),
      field(&F::uniformity_frames, "uniformity_frames", "uniformity-frames",
            "r: a patch's footprint also covers r exemplar frames either side (5)", 0, 1000),
      field(&F::modulation_lower, "modulation_lower", "modulation-lower",
            "m_l of the temporal modulation, as a fraction of the target's larger side (0.01)", 0, 10),
      field(&F::modulation_upper, "modulation_upper", "modulation-upper",
            "m_u of the temporal modulation, as a fraction of the target's larger side (0.1)", 0, 10),
      field(&F::modulation, "modulation", "modulation",
            "temporal modulation: release (1 - m: lagging pixels leave the temporal term) or printed (m)"),
      field(&F::time_shift, "time_shift", "time-shift",
            "exemplar frame advance per output frame: extent (matches the target's motion) or one (always +1)"),
      field(&F::rotate, "rotate", "rotate", "rotate exemplar patches to the target flow (on)"),
      field(&F::flow_smoothing, "flow_smoothing", "flow-smoothing",
            "temporal Gaussian radius in frames of flows made from masks (3)", 0, 100),
      field(&F::bidirectional, "bidirectional", "bidirectional",
            "also solve the shot backward and keep, per pixel, the pass with the lower patch distance"));
  return table;
}

// Engine options of the method: 5 x 5 patches, directed orientations,
// footprint usage, exact (uncompressed) guides, float features.
SynthesisOptions fluidymation_defaults();
inline FluidymationOptions default_fluidymation_options() {
  FluidymationOptions o;
  o.synthesis = fluidymation_defaults();
  return o;
}
void validate(const FluidymationOptions& options);

struct FluidSequence {
  std::vector<ImageView> exemplar;        // S_rgb per frame (the same channels and size), e.g. RGBA
  std::vector<ImageView> exemplar_masks;  // S_mask, 1 channel, > 0.5 = paint
  std::vector<ImageView> exemplar_flows;  // optional: 2 channels, forward; empty = from the masks
  std::vector<ImageView> target_masks;    // T_mask
  std::vector<ImageView> target_flows;    // optional, like exemplar_flows
};

// A frame's matches: 4 channels per target pixel, (i, x, y, phi) = exemplar
// frame, exemplar pixel (sub-pixel), rotation from target to exemplar
// offsets; i = -1 outside the target mask.
using FluidNnf = Image;

struct FluidFrame {
  Image image;      // the exemplar's channels, 0 outside the target mask
  FluidNnf nnf;
  Image time_shift; // delta i* applied to the previous frame's matches (1 channel; 0 in frame 1)
  Image distance;   // the final patch distance per target pixel (1 channel)
  double energy = 0;
};

// The exemplar's flows, shapes, extents, distances and orientations derived
// once; the target's frame by frame as frames are solved (its motion extents
// once: they accumulate along the shot). Frames are solved in order, each
// from the previous frame's matches.
class Fluidymation {
 public:
  Fluidymation(const FluidSequence& sequence, const FluidymationOptions& options);
  ~Fluidymation();
  int frames() const;
  // Frame j from the matches of frame j - 1 (null for the first frame of a
  // pass). progress(fraction of the frame) returning false cancels
  // (CancelledError).
  FluidFrame solve_frame(int j, const FluidNnf* previous, const ProgressCallback& progress = {}) const;
  // SHIFTNNF: the matches of frame j - 1 advanced in exemplar time to frame
  // j; `shift` gets delta i* per pixel.
  FluidNnf shift_nnf(int j, const FluidNnf& previous, Image* shift = nullptr) const;
  Image target_flow(int j) const;  // inside the mask (made from the masks without flows), zero outside
  const Image& exemplar_flow(int i) const;

 private:
  struct Data;
  std::unique_ptr<Data> d_;
};

// The whole sequence (forward, or merged with a backward pass when
// options.bidirectional). progress(fraction) returning false cancels.
std::vector<FluidFrame> stylize_fluid_sequence(const FluidSequence& sequence, const FluidymationOptions& options,
                                               const ProgressCallback& progress = {});

// The engine's energy term of D_dir: weight times the mean over the patch's
// corners and edge midpoints of min(|tan(a_src(p') - phi - a_tgt(q'))|, 1).
std::shared_ptr<const EnergyTerm> make_direction_term(float weight);

// min(|tan a|, 1) for any angle a (radians): D_dir's cost at one point.
float clamped_abs_tan(float a);

}  // namespace tempera

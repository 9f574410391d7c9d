#include "tempera/methods/fluidymation/fluidymation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>

#include "tempera/engine/error.hpp"
#include "tempera/engine/gaussian_blur.hpp"
#include "tempera/methods/fluidymation/mask_flow.hpp"
#include "tempera/methods/fluidymation/motion_extent.hpp"
#include "tempera/methods/fluidymation/signed_distance.hpp"
#include "tempera/engine/solver.hpp"

namespace tempera {

SynthesisOptions fluidymation_defaults() {
  SynthesisOptions o;
  o.patch_size = 5;
  o.axial_orientation = false;  // flows are directions, not axes (see the header)
  o.usage = PatchUsage::None;   // the method adds its own footprint term with the temporal radius
  o.guide_variance = 1.0;       // per-pixel temporal weights need the guides uncompressed
  o.feature_precision = FeaturePrecision::Float;  // rotated patches match in float anyway
  o.em_iterations = 3;
  o.pm_iterations = 2;
  o.em_tolerance = 0;  // every iteration (the early stop is measured for StyLit only)
  return o;
}

void validate(const FluidymationOptions& o) {
  validate_fields(o, fluidymation_option_table());
  validate(o.synthesis);
  if (o.modulation_upper <= o.modulation_lower)
    throw ValueError(concat("modulation_upper (", o.modulation_upper, ") must exceed modulation_lower (",
                            o.modulation_lower, ")"));
}

namespace {

float smoothstep(float v, float lo, float hi) {
  const float t = std::clamp((v - lo) / (hi - lo), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

int clamp_index(float v, int n) { return std::clamp(int(std::lround(v)), 0, n - 1); }

// SHIFTNNF's exemplar time is kept fractional (the paper's is an integer):
// a target slower than the exemplar then advances by, say, half a frame per
// frame instead of rounding down to standing still. Delta i is searched in
// quarter frames, ext interpolated linearly in time.
constexpr float kTimeSteps = 4.0f;

float extent_at(const std::vector<Image>& ext, float t, std::size_t p) {
  const int a = std::clamp(int(std::floor(t)), 0, int(ext.size()) - 1), b = std::min(a + 1, int(ext.size()) - 1);
  const float f = std::clamp(t - float(a), 0.0f, 1.0f);
  return (1 - f) * ext[std::size_t(a)].data()[p] + f * ext[std::size_t(b)].data()[p];
}

}  // namespace

// Without tanf, which took 13% of the method's time (perf at 1 Mpix): tan
// has period pi, so a folds into [0, pi/2], where past pi/4 |tan| >= 1;
// below, tan x = x + x^3 P(x^2), P a least-squares fit of degree 5 on
// [0, pi/4] (relative error under 1e-7 in float, about tanf's). pi is
// subtracted in two parts, the first exact in a few bits, so that k pi is
// exact and the fold loses nothing near the axes.
float clamped_abs_tan(float a) {
  constexpr float kPiHigh = 3.140625f, kPiLow = 9.67653589793e-4f;  // kPiHigh + kPiLow = pi
  const float k = std::nearbyint(a * 0.318309886f);
  const float x = std::abs((a - k * kPiHigh) - k * kPiLow);
  if (x >= 0.785398163f) return 1.0f;
  const float z = x * x;
  const float p =
      ((((0.00935359f * z + 0.00317561f) * z + 0.02439438f) * z + 0.05342145f) * z + 0.13338679f) * z + 0.3333316f;
  return std::min(x + x * z * p, 1.0f);
}

namespace {

// D_dir (Platkevič et al. 2021, §3.2) per candidate: what the rotation about
// the patch centre leaves misaligned across the patch.
class DirectionTerm final : public EnergyTerm {
 public:
  explicit DirectionTerm(float weight) : weight_(weight) {}
  const char* name() const override { return "direction"; }
  bool reads_field() const override { return true; }
  float pair_cost(const LevelContext& c, const OffsetField&, const PairCostBox&, int tx, int ty, int sx, int sy,
                  float) const override {
    const PatchSpace& s = *c.space;
    if (!s.source_angle || !s.target_angle) return 0.0f;
    const int tw = s.target->width, th = s.target->height, sw = s.source->width, sh = s.source->height;
    const float phi = s.rotation(sx, sy, tx, ty), cs = std::cos(phi), sn = std::sin(phi);
    const auto& active = c.constraints->target_active;
    float sum = 0;
    int count = 0;
    // On the patch's corners and edge midpoints (the centre is aligned by
    // construction): a third of the tangents of every patch pixel, and the
    // flows are smooth at that scale.
    for (int dy = -s.radius; dy <= s.radius; dy += s.radius)
      for (int dx = -s.radius; dx <= s.radius; dx += s.radius) {
        const int qx = tx + dx, qy = ty + dy;
        if ((dx == 0 && dy == 0) || qx < 0 || qy < 0 || qx >= tw || qy >= th || !active[std::size_t(qy) * tw + qx])
          continue;
        const int px = std::clamp(int(std::floor(sx + cs * dx - sn * dy + 0.5f)), 0, sw - 1);
        const int py = std::clamp(int(std::floor(sy + sn * dx + cs * dy + 0.5f)), 0, sh - 1);
        const float a = s.source_angle[std::size_t(py) * sw + px] - phi - s.target_angle[std::size_t(qy) * tw + qx];
        sum += clamped_abs_tan(a);  // |tan| is axial; clamped (it diverges at 90 degrees)
        ++count;
      }
    return count ? weight_ * sum / float(count) : 0.0f;
  }

 private:
  float weight_;
};

// What the method derives from one frame's mask and flow (App. A, §3.2-3.3).
struct FrameGuides {
  Image flow, sign, angle, shape, extent, dist;
};

void check_sequence(const std::vector<ImageView>& masks, const std::vector<ImageView>& flows, const char* what) {
  if (masks.size() < 2) throw ValueError(concat("the ", what, " needs at least 2 masks, got ", masks.size()));
  for (std::size_t i = 0; i < masks.size(); ++i) {
    require_nonempty(masks[i], concat(what, " mask ", i));
    if (masks[i].channels != 1) throw ValueError(concat(what, " mask ", i, " must have 1 channel"));
    require_same_size(masks[i], concat(what, " mask ", i), masks[0], concat(what, " mask 0"));
    require_finite(masks[i], concat(what, " mask ", i));
  }
  if (!flows.empty() && flows.size() != masks.size())
    throw ValueError(concat("the ", what, " has ", flows.size(), " flows for ", masks.size(), " masks"));
  for (std::size_t i = 0; i < flows.size(); ++i) {
    if (flows[i].channels != 2) throw ValueError(concat(what, " flow ", i, " must have 2 channels"));
    require_same_size(flows[i], concat(what, " flow ", i), masks[0], concat(what, " mask 0"));
    require_finite(flows[i], concat(what, " flow ", i));
  }
}

// The flow inside the mask, zero outside.
Image masked_flow(const ImageView& flow, const ImageView& mask) {
  Image f = Image::copy_of(flow);
  for (std::size_t p = 0; p < f.pixel_count(); ++p)
    if (mask.data[p] <= 0.5f) f.data()[2 * p] = f.data()[2 * p + 1] = 0;
  return f;
}

FrameGuides derive_frame(const ImageView& mask, Image flow, const ImageView& ext_plus, const ImageView& ext_minus,
                         const FluidymationOptions& o) {
  FrameGuides s;
  s.flow = std::move(flow);
  s.dist = signed_distance(mask);
  const Image g = gradient(s.dist.view());
  const std::size_t n = mask.pixel_count();
  s.sign = Image(mask.width, mask.height, 1);
  s.angle = Image(mask.width, mask.height, 1);
  s.extent = Image(mask.width, mask.height, 2);
  for (std::size_t p = 0; p < n; ++p) {
    const float fx = s.flow.data()[2 * p], fy = s.flow.data()[2 * p + 1];
    // The distance gradient points inward: a flow against it spreads the material.
    const float sg = fx * g.data()[2 * p] + fy * g.data()[2 * p + 1] <= 0.0f ? 1.0f : -1.0f;
    s.sign.data()[p] = sg;
    s.angle.data()[p] = std::atan2(sg * fy, sg * fx);
    const float plus = ext_plus.data[p] / o.extent_scale, minus = ext_minus.data[p] / o.extent_scale;
    s.extent.data()[2 * p] = sg > 0 ? plus : minus;
    s.extent.data()[2 * p + 1] = sg > 0 ? minus : plus;
  }
  s.shape = gaussian_blur(mask, o.shape_blur / 3.0f);
  return s;
}

// The exemplar's guides, every frame's at once: any frame is matched.
struct ExemplarGuides {
  std::vector<FrameGuides> frames;
  MotionExtent ext;  // ext+ / ext- in pixels

  ExemplarGuides(const std::vector<ImageView>& masks, const std::vector<ImageView>& flows,
                 const FluidymationOptions& o) {
    std::vector<Image> flow;
    if (flows.empty()) flow = flow_from_masks(masks, o.flow_smoothing);
    for (std::size_t i = 0; i < flows.size(); ++i) flow.push_back(masked_flow(flows[i], masks[i]));
    std::vector<ImageView> fv;
    for (const Image& f : flow) fv.push_back(f.view());
    ext = motion_extent(fv, masks);
    for (std::size_t i = 0; i < masks.size(); ++i)
      frames.push_back(derive_frame(masks[i], std::move(flow[i]), ext.forward[i].view(), ext.backward[i].view(), o));
  }
};

// The target's guides, derived when a frame is solved and kept for the next
// (SHIFTNNF reads frame j - 1's): only the motion extents, and a flow made
// from the masks, span the shot (all of it was held: 40 bytes a pixel and
// frame, 513 MB for 24 frames of 0.25 Mpix).
class TargetGuides {
 public:
  TargetGuides(const std::vector<ImageView>& masks, const std::vector<ImageView>& flows, const FluidymationOptions& o)
      : masks_(masks), flows_(flows), o_(o) {
    if (flows_.empty()) mask_flows_ = flow_from_masks(masks, o.flow_smoothing);
    ext_ = motion_extent([&](std::size_t i) { return flow(i); }, masks);
  }

  Image flow(std::size_t j) const {
    return flows_.empty() ? Image::copy_of(mask_flows_.at(j).view()) : masked_flow(flows_.at(j), masks_.at(j));
  }
  const MotionExtent& ext() const { return ext_; }

  std::shared_ptr<const FrameGuides> frame(std::size_t j) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [index, guides] : recent_)
      if (guides && index == j) return guides;
    auto guides = std::make_shared<const FrameGuides>(
        derive_frame(masks_.at(j), flow(j), ext_.forward[j].view(), ext_.backward[j].view(), o_));
    recent_[oldest_] = {j, guides};
    oldest_ ^= 1;
    return guides;
  }

 private:
  std::vector<ImageView> masks_, flows_;
  FluidymationOptions o_;
  std::vector<Image> mask_flows_;  // when the flows are made from the masks (App. A): across frames
  MotionExtent ext_;
  mutable std::mutex mutex_;
  mutable std::pair<std::size_t, std::shared_ptr<const FrameGuides>> recent_[2];
  mutable int oldest_ = 0;
};

}  // namespace

struct Fluidymation::Data {
  FluidSequence seq;
  FluidymationOptions o;
  std::optional<ExemplarGuides> S;
  std::optional<TargetGuides> T;
  int tw = 0, th = 0;

  Image temporal_weight(const FrameGuides& target, int j, const FluidNnf& shifted, const Image& voted) const;
  SynthesisInput input(const FrameGuides& target, int j, const Image* temporal, const Image* weight) const;
  void read_matches(const FrameGuides& target, int j, const Solver& solver, const LevelResult& r,
                    const std::optional<FluidNnf>& shifted, FluidFrame& out) const;
};

Fluidymation::Fluidymation(const FluidSequence& seq, const FluidymationOptions& o) : d_(new Data) {
  validate(o);
  if (seq.exemplar.size() != seq.exemplar_masks.size())
    throw ValueError(concat("the exemplar has ", seq.exemplar.size(), " frames and ", seq.exemplar_masks.size(),
                            " masks"));
  check_sequence(seq.exemplar_masks, seq.exemplar_flows, "exemplar");
  check_sequence(seq.target_masks, seq.target_flows, "target");
  for (std::size_t i = 0; i < seq.exemplar.size(); ++i) {
    require_nonempty(seq.exemplar[i], concat("exemplar frame ", i));
    require_same_size(seq.exemplar[i], concat("exemplar frame ", i), seq.exemplar_masks[0], "exemplar mask 0");
    if (seq.exemplar[i].channels != seq.exemplar[0].channels)
      throw ValueError(concat("exemplar frame ", i, " has ", seq.exemplar[i].channels, " channels, frame 0 ",
                              seq.exemplar[0].channels));
  }
  d_->seq = seq;
  d_->o = o;
  d_->S.emplace(seq.exemplar_masks, seq.exemplar_flows, o);
  d_->T.emplace(seq.target_masks, seq.target_flows, o);
  d_->tw = seq.target_masks[0].width;
  d_->th = seq.target_masks[0].height;
}

Fluidymation::~Fluidymation() = default;
int Fluidymation::frames() const { return int(d_->seq.target_masks.size()); }
Image Fluidymation::target_flow(int j) const { return d_->T->flow(std::size_t(j)); }
const Image& Fluidymation::exemplar_flow(int i) const { return d_->S->frames.at(std::size_t(i)).flow; }

FluidNnf Fluidymation::shift_nnf(int j, const FluidNnf& prev, Image* shift) const {
  const Data& d = *d_;
  if (j < 1 || j >= frames()) throw ValueError(concat("SHIFTNNF needs a frame 1 to ", frames() - 1, ", got ", j));
  if (prev.width() != d.tw || prev.height() != d.th || prev.channels() != 4)
    throw ValueError(concat("previous matches must be ", d.tw, "x", d.th, " with 4 channels (i, x, y, phi)"));
  const int ns = int(d.seq.exemplar.size());
  const int sw = d.seq.exemplar[0].width, sh = d.seq.exemplar[0].height;
  FluidNnf out = prev;
  if (shift) *shift = Image(d.tw, d.th, 1);
  const std::shared_ptr<const FrameGuides> before = d.T->frame(std::size_t(j - 1));
  const std::vector<Image>& target_ext = d.T->ext().forward;
  for (std::size_t q = 0; q < prev.pixel_count(); ++q) {
    const float* m = prev.data() + 4 * q;
    if (m[0] < 0) continue;
    const float i0 = std::clamp(m[0], 0.0f, float(ns - 1));
    const std::size_t p = std::size_t(clamp_index(m[2], sh)) * sw + std::size_t(clamp_index(m[1], sw));
    // Same expansion sense: play the exemplar forward on ext+; opposite: backward on ext-.
    const bool forward = before->sign.data()[q] == d.S->frames[std::size_t(std::lround(i0))].sign.data()[p];
    const std::vector<Image>& ext = forward ? d.S->ext.forward : d.S->ext.backward;
    const float step = forward ? 1.0f : -1.0f, last = forward ? float(ns - 1) - i0 : i0;
    float best = 0;
    if (d.o.time_shift == TimeShift::One) {
      best = std::min(1.0f, last);
    } else {
      const float target = target_ext[std::size_t(j)].data()[q] - target_ext[std::size_t(j - 1)].data()[q];
      const float from = extent_at(ext, i0, p);
      float best_cost = std::numeric_limits<float>::infinity();
      for (int k = 0; k <= int(std::ceil(last * kTimeSteps)); ++k) {
        const float t = std::min(last, float(k) / kTimeSteps);
        const float cost = std::abs(target - std::abs(extent_at(ext, i0 + step * t, p) - from));
        if (cost < best_cost) best_cost = cost, best = t;
      }
    }
    out.data()[4 * q] = i0 + step * best;
    if (shift) shift->data()[q] = step * best;
  }
  return out;
}

namespace {

// VOTE(S_rgb, nnf) (mean voting with each neighbour's rotation) at the
// target's size, and where anything voted. A fractional exemplar time votes
// the two frames around it, linearly: rounded, a target at half the
// exemplar's speed would see its temporal guide stand still and then jump.
Image vote_matches(const FluidSequence& seq, const FluidNnf& nnf, int radius, Image& voted) {
  const int w = nnf.width(), h = nnf.height(), ch = seq.exemplar[0].channels;
  const int sw = seq.exemplar[0].width, sh = seq.exemplar[0].height, ns = int(seq.exemplar.size());
  Image out(w, h, ch);
  voted = Image(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::vector<double> sum(std::size_t(ch), 0.0);
      int count = 0;
      for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const float* m = nnf.pixel(nx, ny);
          if (m[0] < 0) continue;
          const float cs = std::cos(m[3]), sn = std::sin(m[3]);
          // The neighbour's source patch, shifted back by d in source space.
          const int px = clamp_index(m[1] - (cs * dx - sn * dy), sw), py = clamp_index(m[2] - (sn * dx + cs * dy), sh);
          const int a = std::clamp(int(std::floor(m[0])), 0, ns - 1), b = std::min(a + 1, ns - 1);
          const float f = std::clamp(m[0] - float(a), 0.0f, 1.0f);
          const float* sa = seq.exemplar[std::size_t(a)].pixel(px, py);
          const float* sb = seq.exemplar[std::size_t(b)].pixel(px, py);
          for (int c = 0; c < ch; ++c) sum[std::size_t(c)] += (1 - f) * sa[c] + f * sb[c];
          ++count;
        }
      if (!count) continue;
      voted.at(x, y, 0) = 1.0f;
      for (int c = 0; c < ch; ++c) out.at(x, y, c) = float(sum[std::size_t(c)] / count);
    }
  return out;
}

// NNF_prev at level `l`: each level pixel picks the full-size pixel under
// its centre (DOWNSCALE; the paper's mode over the 2^l window would need
// votes per cell) and scales the exemplar position to the level.
OffsetField level_field(const Solver& solver, int l, const FluidNnf& nnf, CandidateList* candidates) {
  const int w = solver.target_width(l), h = solver.target_height(l);
  OffsetField f(w, h);
  if (candidates) candidates->begin.assign(std::size_t(w) * h + 1, 0);
  const SourceLayout &fine = solver.layout(0), &here = solver.layout(l);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = f.index(x, y);
      const float* m = nnf.pixel(std::min(nnf.width() - 1, int((x + 0.5) * nnf.width() / w)),
                                 std::min(nnf.height() - 1, int((y + 0.5) * nnf.height() / h)));
      f.dist[i] = std::numeric_limits<float>::infinity();
      if (candidates) candidates->begin[i + 1] = candidates->begin[i];
      if (m[0] < 0) {
        f.x[i] = -1;  // no previous match: legalize_field gives it a valid source
        continue;
      }
      const std::size_t e = std::size_t(clamp_index(m[0], int(here.rects.size())));
      const float sx = float(here.rects[e].width) / float(fine.rects[e].width);
      const float sy = float(here.rects[e].height) / float(fine.rects[e].height);
      float ax, ay;
      solver.to_atlas(l, int(e), (m[1] + 0.5f) * sx - 0.5f, (m[2] + 0.5f) * sy - 0.5f, ax, ay);
      f.set_position(i, ax, ay);
      if (candidates) {
        candidates->x.push_back(f.x[i]);
        candidates->y.push_back(f.y[i]);
        ++candidates->begin[i + 1];
      }
    }
  return f;
}

}  // namespace

// w_t m(q) per target pixel: 0 where the previous mask was empty or nothing
// voted, else the smoothstep of the distance-field mismatch (or 1 - it).
Image Fluidymation::Data::temporal_weight(const FrameGuides& target, int j, const FluidNnf& shifted,
                                          const Image& voted) const {
  Image weight(tw, th, 1);
  const float d_max = float(std::max(tw, th)), lo = o.modulation_lower * d_max, hi = o.modulation_upper * d_max;
  const ImageView& before = seq.target_masks[std::size_t(j - 1)];
  const int ns = int(seq.exemplar.size()), sw = seq.exemplar[0].width, sh = seq.exemplar[0].height;
  for (std::size_t q = 0; q < weight.pixel_count(); ++q) {
    const float* m = shifted.data() + 4 * q;
    if (before.data[q] <= 0.5f || voted.data()[q] <= 0 || m[0] < 0) continue;
    const std::size_t p = std::size_t(clamp_index(m[2], sh)) * sw + std::size_t(clamp_index(m[1], sw));
    const float mismatch = std::abs(target.dist.data()[q] - S->frames[std::size_t(clamp_index(m[0], ns))].dist.data()[p]);
    const float s = smoothstep(mismatch, lo, hi);
    weight.data()[q] = o.modulation == TemporalModulation::Release ? 1.0f - s : s;
  }
  return weight;
}

// The engine's input of frame j: the exemplar video as the source set with
// its guides (shape, extent and, with a temporal guide, its RGB), the
// target's guides, masks, orientations and the method's terms.
SynthesisInput Fluidymation::Data::input(const FrameGuides& target, int j, const Image* temporal,
                                         const Image* weight) const {
  SynthesisInput in;
  in.style = seq.exemplar[0];
  const std::vector<FrameGuides>& source = S->frames;
  in.guides.add("shape", source[0].shape.view(), target.shape.view(), o.boundary_weight);
  in.guides.add("extent", source[0].extent.view(), target.extent.view(), o.extent_weight);
  if (temporal) {
    in.guides.add("temporal", seq.exemplar[0], temporal->view(), o.temporal_weight);
    in.target_weight_maps = {ImageView{}, ImageView{}, weight->view()};
  }
  in.source_mask = seq.exemplar_masks[0];
  in.target_mask = seq.target_masks[std::size_t(j)];
  if (o.rotate) {
    in.source_orientation = source[0].angle.view();
    in.target_orientation = target.angle.view();
  }
  in.sequence = 0;
  in.time = 0;
  for (std::size_t i = 1; i < seq.exemplar.size(); ++i) {
    Exemplar e;
    e.style = seq.exemplar[i];
    e.guides = {source[i].shape.view(), source[i].extent.view()};
    if (temporal) e.guides.push_back(e.style);
    e.mask = seq.exemplar_masks[i];
    if (o.rotate) e.orientation = source[i].angle.view();
    e.sequence = 0;
    e.time = int(i);
    in.exemplars.push_back(e);
  }
  if (o.uniformity_weight > 0) in.terms.push_back(make_footprint_usage(o.uniformity_weight, o.uniformity_frames));
  if (o.direction_weight > 0 && o.rotate) in.terms.push_back(make_direction_term(o.direction_weight));
  return in;
}

namespace {

// Coarse to fine: the coarsest level cold (frame 1) or from NNF_prev; each
// finer level from the coarser field upscaled, with NNF_prev as candidates.
LevelResult solve_levels(const Solver& solver, const std::optional<FluidNnf>& shifted, const ProgressCallback& progress) {
  LevelResult r;
  const int levels = solver.levels();
  for (int l = solver.coarsest(); l >= 0; --l) {
    LevelStart start;
    OffsetField prev_here, up;
    CandidateList candidates;
    const bool coarsest = l == solver.coarsest();
    if (shifted) prev_here = level_field(solver, l, *shifted, coarsest ? nullptr : &candidates);
    if (!coarsest) {
      up = solver.resample(r.field, l + 1, l);
      start.field = &up;
      if (shifted) start.candidates = &candidates;
    } else if (shifted) {
      start.field = &prev_here;
    }
    const int done = solver.coarsest() - l;
    ProgressCallback level_progress;
    if (progress) level_progress = [&](double f) { return progress((done + f) / levels); };
    r = solver.solve_level(l, start, level_progress);
  }
  return r;
}

}  // namespace

// The finest level's matches as (i, x, y, phi), 0 (and i = -1) outside the mask.
void Fluidymation::Data::read_matches(const FrameGuides& target, int j, const Solver& solver, const LevelResult& r,
                                      const std::optional<FluidNnf>& shifted, FluidFrame& out) const {
  const int ns = int(seq.exemplar.size());
  out.energy = r.stats.energy.empty() ? 0.0 : r.stats.energy.back();
  out.image = r.image;
  out.nnf = Image(tw, th, 4, 0.0f);
  out.distance = Image(tw, th, 1);
  const ImageView& mask = seq.target_masks[std::size_t(j)];
  const int ch = out.image.channels();
  for (std::size_t q = 0; q < out.nnf.pixel_count(); ++q) {
    float* m = out.nnf.data() + 4 * q;
    out.distance.data()[q] = r.field.dist[q];
    if (mask.data[q] <= 0.5f) {
      m[0] = -1;
      std::fill_n(out.image.data() + q * std::size_t(ch), ch, 0.0f);
      continue;
    }
    const ExemplarMatch e = solver.match(0, r.field, q);
    m[0] = float(e.exemplar), m[1] = e.x, m[2] = e.y;
    // A pixel that kept its shifted match keeps its fractional exemplar time.
    if (shifted) {
      const float* sm = shifted->data() + 4 * q;
      if (sm[0] >= 0 && clamp_index(sm[0], ns) == e.exemplar && std::abs(sm[1] - e.x) < 1 && std::abs(sm[2] - e.y) < 1)
        m[0] = sm[0];
    }
    if (o.rotate) {
      const Image& a = S->frames[std::size_t(e.exemplar)].angle;
      m[3] = a.at(clamp_index(e.x, a.width()), clamp_index(e.y, a.height()), 0) - target.angle.data()[q];
    }
  }
}

namespace {

bool any_inside(const ImageView& mask) {  // as the solver counts a target pixel
  for (std::size_t i = 0; i < mask.size(); ++i)
    if (mask.data[i] > 0.5f) return true;
  return false;
}

FluidFrame empty_frame(int width, int height, int channels) {
  FluidFrame out;
  out.image = Image(width, height, channels, 0.0f);
  out.nnf = Image(width, height, 4, 0.0f);
  out.time_shift = Image(width, height, 1, 0.0f);
  out.distance = Image(width, height, 1, 0.0f);
  return out;
}

}  // namespace

FluidFrame Fluidymation::solve_frame(int j, const FluidNnf* previous, const ProgressCallback& progress) const {
  const Data& d = *d_;
  if (j < 0 || j >= frames()) throw ValueError(concat("frame ", j, " is outside the target's 0 to ", frames() - 1));
  if (previous && j == 0) throw ValueError("the first frame has no previous frame");
  // An empty target mask (the object off screen) gives a transparent frame,
  // as in LazyFluids; the frame after it starts afresh, as the first does.
  if (!any_inside(d.seq.target_masks[std::size_t(j)])) return empty_frame(d.tw, d.th, d.seq.exemplar[0].channels);
  if (previous && !any_inside(d.seq.target_masks[std::size_t(j - 1)])) previous = nullptr;
  FluidFrame out;
  std::optional<FluidNnf> shifted;
  if (previous) shifted = shift_nnf(j, *previous, &out.time_shift);  // first: it derives frame j - 1's guides
  else out.time_shift = Image(d.tw, d.th, 1);
  const std::shared_ptr<const FrameGuides> target = d.T->frame(std::size_t(j));
  Image temporal, weight;
  const bool use_temporal = shifted && d.o.temporal_weight > 0;
  if (use_temporal) {
    Image voted;
    temporal = vote_matches(d.seq, *shifted, d.o.synthesis.patch_size / 2, voted);
    weight = d.temporal_weight(*target, j, *shifted, voted);
  }
  SynthesisOptions so = d.o.synthesis;
  so.seed = d.o.synthesis.seed + std::uint64_t(j) * 0x9E3779B97F4A7C15ull;
  const Solver solver(d.input(*target, j, use_temporal ? &temporal : nullptr, &weight), so);
  d.read_matches(*target, j, solver, solve_levels(solver, shifted, progress), shifted, out);
  return out;
}

namespace {

// The target played backward: masks reversed, and each reversed frame's
// forward flow the negated flow of the frame (an approximation where the
// flow changes fast: the exact one would be the next frame's V-).
struct Reversed {
  FluidSequence seq;
  std::vector<Image> flows;
};

Reversed reversed(const FluidSequence& seq, const Fluidymation& forward) {
  Reversed r;
  r.seq = seq;
  std::reverse(r.seq.target_masks.begin(), r.seq.target_masks.end());
  r.seq.target_flows.clear();
  r.seq.exemplar_flows.clear();
  const int n = int(seq.target_masks.size());
  for (int k = 0; k < n; ++k) {
    Image f = forward.target_flow(n - 1 - k);
    for (std::size_t p = 0; p < f.pixel_count() * 2; ++p) f.data()[p] = -f.data()[p];
    r.flows.push_back(std::move(f));
  }
  for (const Image& f : r.flows) r.seq.target_flows.push_back(f.view());
  for (int i = 0; i < int(seq.exemplar.size()); ++i) r.seq.exemplar_flows.push_back(forward.exemplar_flow(i).view());
  return r;
}

std::vector<FluidFrame> run_pass(const Fluidymation& f, const ProgressCallback& progress, double first, double span) {
  std::vector<FluidFrame> out;
  const int n = f.frames();
  for (int j = 0; j < n; ++j) {
    ProgressCallback p;
    if (progress) p = [&](double x) { return progress(first + span * (j + x) / n); };
    out.push_back(f.solve_frame(j, j ? &out.back().nnf : nullptr, p));
  }
  return out;
}

}  // namespace

std::vector<FluidFrame> stylize_fluid_sequence(const FluidSequence& seq, const FluidymationOptions& o,
                                               const ProgressCallback& progress) {
  const Fluidymation forward(seq, o);
  if (!o.bidirectional) return run_pass(forward, progress, 0.0, 1.0);
  std::vector<FluidFrame> out = run_pass(forward, progress, 0.0, 0.5);
  const Reversed rev = reversed(seq, forward);
  const Fluidymation backward(rev.seq, o);
  std::vector<FluidFrame> back = run_pass(backward, progress, 0.5, 0.5);
  std::reverse(back.begin(), back.end());
  // Merge: per pixel, the pass whose match has the lower patch distance.
  for (std::size_t j = 0; j < out.size(); ++j) {
    FluidFrame &a = out[j], &b = back[j];
    const int ch = a.image.channels();
    for (std::size_t q = 0; q < a.distance.pixel_count(); ++q) {
      if (!(b.distance.data()[q] < a.distance.data()[q])) continue;
      std::copy_n(b.image.data() + q * ch, ch, a.image.data() + q * ch);
      std::copy_n(b.nnf.data() + 4 * q, 4, a.nnf.data() + 4 * q);
      a.distance.data()[q] = b.distance.data()[q];
      a.time_shift.data()[q] = -b.time_shift.data()[q];
    }
  }
  return out;
}

std::shared_ptr<const EnergyTerm> make_direction_term(float weight) { return std::make_shared<DirectionTerm>(weight); }

}  // namespace tempera

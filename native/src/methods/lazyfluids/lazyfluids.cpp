#include "tempera/methods/lazyfluids/lazyfluids.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

#include "tempera/engine/error.hpp"
#include "tempera/engine/patch_distance.hpp"  // sample_bilinear
#include "tempera/engine/pyramid.hpp"

namespace tempera {

namespace {

constexpr int kAlpha = 3;  // the alpha channel of RGBA

// EM iterations of a warm-started frame's one level. Measured on the chimney
// shot at 512x384 (frames 14-36, bench/bench_lazyfluids.py --shot,
// docs/benchmarks.md): against cold frames' energy, 3 end 0.2% above at
// 2.3x their speed, 4 0.3% below, 6 (all) 0.4% below at 1.4x.
constexpr int kWarmEmIterations = 3;

void require_channels(const ImageView& image, int channels, const char* what) {
  require_nonempty(image, what);
  if (image.channels != channels)
    throw ValueError(concat(what, " must have ", channels, " channel(s), got ", image.channels));
  require_finite(image, what);
}

AlphaSegmentOptions segment_options(const LazyFluidsOptions& o) { return {o.alpha_radius, o.alpha_lower, o.alpha_upper}; }

// Channel `c` of `image` as a 1-channel image.
Image channel(const ImageView& image, int c) { return extract_channels(image, c, 1); }

// A copy of RGBA `image` with alpha multiplied by `scale`: the squared
// alpha difference of a guide then weighs scale² (eq. 5.9's 3‖Δa‖²).
Image scale_alpha(const ImageView& image, float scale) {
  Image out = Image::copy_of(image);
  for (std::size_t i = 0; i < out.pixel_count(); ++i) out.data()[i * 4 + kAlpha] *= scale;
  return out;
}

// One exemplar of the source set with everything the engine needs from it;
// the images live in `keep`.
Exemplar source_exemplar(const ImageView& style, const ImageView& previous_style, bool temporal,
                         const LazyFluidsOptions& o, int quarter_turns, std::deque<Image>& keep) {
  auto kept = [&](Image image) { return keep.emplace_back(rotate_quarter_turns(image.view(), quarter_turns)).view(); };
  const AlphaSegments seg = alpha_segments(channel(style, kAlpha).view(), segment_options(o));
  Exemplar e;
  e.style = kept(Image::copy_of(style));
  e.guides.push_back(kept(Image::copy_of(seg.blurred.view())));
  if (temporal) e.guides.push_back(kept(scale_alpha(previous_style, std::sqrt(o.alpha_weight))));
  e.mask = kept(Image::copy_of(seg.inside.view()));
  e.segments = kept(Image::copy_of(seg.segments.view()));
  return e;
}

// Pixels outside the target (label -1) come out transparent in every channel.
void clear_outside(Image& image, const Image& labels) {
  const int c = image.channels();
  for (std::size_t i = 0; i < labels.pixel_count(); ++i)
    if (labels.data()[i] < 0) std::fill_n(image.data() + i * std::size_t(c), c, 0.0f);
}

// Valid patch centres (inside, `radius` from the border) with `label` at
// pyramid level `level`, the labels picked every 1/ratio^level pixels as the
// engine's label pyramid picks them.
int centres_at_level(const AlphaSegments& s, float label, int level, double ratio, int radius) {
  const int w = s.labels.width(), h = s.labels.height();
  const auto [lw, lh] = level_sizes(w, h, level + 1, ratio).back();
  const double scale = std::pow(1.0 / ratio, level);
  int n = 0;
  for (int y = radius; y < lh - radius; ++y)
    for (int x = radius; x < lw - radius; ++x)
      n += s.labels.at(std::min(w - 1, int(x * scale)), std::min(h - 1, int(y * scale)), 0) == label;
  return n;
}

bool has_label(const AlphaSegments& s, float label) {
  return std::find(s.labels.data(), s.labels.data() + s.labels.pixel_count(), label) !=
         s.labels.data() + s.labels.pixel_count();
}

// The engine's automatic level count, less the coarse levels where the
// exemplar would keep too few patches of a segment the target has (a small
// exemplar's boundary ring or interior vanishes when downsampled). ValueError
// when even the full-size exemplar has none.
int fluid_levels(const AlphaSegments& exemplar, const AlphaSegments& target, const SynthesisOptions& o) {
  const int radius = o.patch_size / 2, min_side = 4 * o.patch_size;
  for (const float label : {boundary_label, interior_label})
    if (has_label(target, label) && centres_at_level(exemplar, label, 0, o.level_ratio, radius) == 0)
      throw ValueError(concat("the exemplar has no ", label == interior_label ? "interior" : "boundary",
                              " patches (blurred alpha ", label == interior_label ? ">= alpha_upper" : "between the thresholds",
                              ") but the target has: use a larger exemplar, a smaller alpha_radius or other thresholds"));
  if (o.levels > 0) return o.levels;
  int levels = std::min(pyramid_levels_for(target.labels.width(), target.labels.height(), min_side, 12, o.level_ratio),
                        pyramid_levels_for(exemplar.labels.width(), exemplar.labels.height(), min_side, 12, o.level_ratio));
  const auto enough = [&](int level) {
    for (const float label : {boundary_label, interior_label})
      if (has_label(target, label) && centres_at_level(exemplar, label, level, o.level_ratio, radius) < 4) return false;
    return true;
  };
  while (levels > 1 && !enough(levels - 1)) --levels;
  return levels;
}

}  // namespace

SynthesisOptions lazyfluids_defaults() {
  SynthesisOptions o;
  o.patch_size = 5;
  o.usage = PatchUsage::Uniform;
  o.style_channel_weights = {1, 1, 1, 3};
  o.guide_variance = 1;  // per-pixel λ_q maps need the guides uncompressed anyway
  o.em_tolerance = 0;    // every iteration of a cold frame (the early stop is measured for StyLit only)
  return o;
}

LazyFluidsOptions default_lazyfluids_options() {
  LazyFluidsOptions o;
  o.synthesis = lazyfluids_defaults();
  return o;
}

bool warm_starts(const LazyFluidsOptions& o) { return o.warm_start && o.temporal_weight > 0; }

void validate(const LazyFluidsOptions& o) {
  validate_fields(o, lazyfluids_option_table());
  if (!(o.alpha_lower < o.alpha_upper))
    throw ValueError(concat("alpha_lower (", o.alpha_lower, ") must be below alpha_upper (", o.alpha_upper, ")"));
  validate(o.synthesis);
}

Image temporal_weights(const ImageView& target_alpha, const ImageView& advected, float lambda) {
  require_channels(target_alpha, 1, "target alpha");
  require_nonempty(advected, "advected previous frame");
  require_same_size(target_alpha, "target alpha", advected, "advected previous frame");
  const int a = advected.channels == 1 ? 0 : kAlpha;
  if (advected.channels != 1 && advected.channels != 4)
    throw ValueError(concat("advected previous frame must be RGBA or alpha, got ", advected.channels, " channels"));
  Image out(target_alpha.width, target_alpha.height, 1);
  for (std::size_t i = 0; i < out.pixel_count(); ++i) {
    const float appearing = std::max(0.0f, target_alpha.data[i] - advected.data[i * std::size_t(advected.channels) + a]);
    out.data()[i] = (1.0f - appearing) * lambda;
  }
  return out;
}

Image advect_output(const ImageView& previous, const ImageView& flow) {
  require_nonempty(previous, "previous output");
  require_channels(flow, 2, "flow");
  require_same_size(previous, "previous output", flow, "flow");
  const int w = previous.width, h = previous.height;
  Image out(w, h, previous.channels);  // zero: what comes from outside the frame
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* f = flow.pixel(x, y);
      const float sx = float(x) - f[0], sy = float(y) - f[1];
      if (sx >= -0.5f && sx < float(w) - 0.5f && sy >= -0.5f && sy < float(h) - 0.5f)
        sample_bilinear(previous.data, w, h, previous.channels, previous.channels, sx, sy, out.pixel(x, y));
    }
  return out;
}

Image rotate_quarter_turns(const ImageView& image, int quarter_turns) {
  require_nonempty(image, "image to rotate");
  const int turns = ((quarter_turns % 4) + 4) % 4;
  const int w = image.width, h = image.height, c = image.channels;
  Image out(turns % 2 ? h : w, turns % 2 ? w : h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // Clockwise in image coordinates (y down): (x, y) -> (h - 1 - y, x).
      const int ox = turns == 0 ? x : turns == 1 ? h - 1 - y : turns == 2 ? w - 1 - x : y;
      const int oy = turns == 0 ? y : turns == 1 ? x : turns == 2 ? h - 1 - y : w - 1 - x;
      std::copy_n(image.pixel(x, y), c, out.pixel(ox, oy));
    }
  return out;
}

Image motion_blur_along_flow(const ImageView& image, const ImageView& flow, float length) {
  require_nonempty(image, "image to blur");
  require_channels(flow, 2, "flow");
  require_same_size(image, "image to blur", flow, "flow");
  if (!(length > 0)) return Image::copy_of(image);
  const int w = image.width, h = image.height, c = image.channels;
  const int steps = std::max(1, int(std::lround(length / 2)));
  Image out(w, h, c);
  std::vector<float> sample(static_cast<std::size_t>(c)), v(2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* o = out.pixel(x, y);
      std::copy_n(image.pixel(x, y), c, o);
      int count = 1;
      for (const float direction : {1.0f, -1.0f}) {
        float px = float(x), py = float(y);
        for (int s = 0; s < steps; ++s) {
          sample_bilinear(flow.data, w, h, 2, 2, px, py, v.data());
          const float speed = std::hypot(v[0], v[1]);
          if (speed < 0.01f) break;
          px += direction * v[0] / speed, py += direction * v[1] / speed;
          sample_bilinear(image.data, w, h, c, c, px, py, sample.data());
          for (int ch = 0; ch < c; ++ch) o[ch] += sample[std::size_t(ch)];
          ++count;
        }
      }
      for (int ch = 0; ch < c; ++ch) o[ch] /= float(count);
    }
  return out;
}

namespace {

void check_frame_input(const FluidFrameInput& in) {
  require_channels(in.style, 4, "exemplar (RGBA)");
  require_channels(in.previous_style, 4, "previous exemplar frame (RGBA)");
  require_same_size(in.style, "exemplar", in.previous_style, "previous exemplar frame");
  require_channels(in.target_alpha, 1, "target alpha");
  if (!in.advected.empty()) require_same_size(in.target_alpha, "target alpha", in.advected, "advected previous frame");
}

// Eq. 5.9 on the engine: the RGBA style, the blurred-alpha guide (η), the
// temporal guide weighted by λ_q, segments and masks; rotated copies of the
// exemplar as further sources. Images it makes live in `keep`.
SynthesisInput fluid_synthesis_input(const FluidFrameInput& in, const AlphaSegments& target,
                                     const FluidFrameResult& result, bool temporal, const LazyFluidsOptions& o,
                                     std::deque<Image>& keep) {
  const Exemplar main = source_exemplar(in.style, in.previous_style, temporal, o, 0, keep);
  SynthesisInput si;
  si.style = main.style;
  si.guides.add("blurred_alpha", main.guides[0], target.blurred.view(), o.alpha_guide_weight);
  if (temporal) {
    const Image& advected = keep.emplace_back(scale_alpha(in.advected, std::sqrt(o.alpha_weight)));
    si.guides.add("advected_previous", main.guides[1], advected.view(), 1.0f);
    si.target_weight_maps = {ImageView{}, result.temporal_weights.view()};
  }
  si.source_mask = main.mask;
  si.source_segments = main.segments;
  si.target_mask = target.inside.view();
  si.target_segments = target.segments.view();
  if (o.rotations)
    for (int turns = 1; turns < 4; ++turns)
      si.exemplars.push_back(source_exemplar(in.style, in.previous_style, temporal, o, turns, keep));
  return si;
}

}  // namespace

FluidFrameResult stylize_fluid_frame(const FluidFrameInput& in, const LazyFluidsOptions& o,
                                     const ProgressCallback& progress) {
  validate(o);
  check_frame_input(in);
  const bool temporal = !in.advected.empty() && o.temporal_weight > 0;
  FluidFrameResult result;
  const AlphaSegments target = alpha_segments(in.target_alpha, segment_options(o));
  result.target_labels = target.labels;
  result.temporal_weights = temporal ? temporal_weights(in.target_alpha, in.advected, o.temporal_weight)
                                     : Image(in.target_alpha.width, in.target_alpha.height, 1, 0.0f);
  result.image = Image(in.target_alpha.width, in.target_alpha.height, 4, 0.0f);
  const float* inside = target.inside.data();
  if (std::none_of(inside, inside + target.inside.pixel_count(), [](float v) { return v > 0.5f; }))
    return result;  // nothing to synthesize: a transparent frame

  std::deque<Image> keep;
  const SynthesisInput si = fluid_synthesis_input(in, target, result, temporal, o, keep);
  SynthesisOptions engine = o.synthesis;
  engine.style_channel_weights.resize(4, 1.0f);  // alpha_weight owns the alpha channel's
  engine.style_channel_weights[kAlpha] = o.alpha_weight;
  engine.levels = fluid_levels(alpha_segments(channel(in.style, kAlpha).view(), segment_options(o)), target, engine);
  const bool warm = warm_starts(o) && temporal && in.previous_field && !in.previous_field->x.empty();
  if (warm) {
    require_channels(in.flow_previous, 2, "previous flow");
    engine.em_schedule.clear();
    engine.em_iterations = std::min(engine.em_iterations, kWarmEmIterations);
  }
  // Warm: the finest level from the previous frame's field advected along
  // F^{t-1} (the semi-Lagrangian stand-in for V-, as for the advected output).
  // Where the advected previous output holds no material (its alpha below a
  // half: at an emitter, or where the plume spreads) nothing carried a match
  // there, so those pixels start afresh, as a shot's newly visible ones do
  // (χ-). Measured against restarting only where alpha rose by a half, and
  // against no restart: the lowest energy of the three (docs/benchmarks.md).
  const Image carried = warm ? channel(in.advected, kAlpha) : Image();
  result.synthesis = warm ? synthesize_warm(si, engine, *in.previous_field, in.flow_previous, carried.view(), progress)
                          : synthesize(si, engine, progress);
  result.image = Image::copy_of(result.synthesis.image.view());
  clear_outside(result.image, target.labels);
  return result;
}

std::vector<Image> stylize_fluid_sequence(const std::vector<ImageView>& exemplar, const std::vector<ImageView>& alphas,
                                          const std::vector<ImageView>& flows, const LazyFluidsOptions& o,
                                          const ProgressCallback& progress) {
  validate(o);
  if (exemplar.empty()) throw ValueError("the exemplar has no frames");
  if (alphas.empty()) throw ValueError("no target alpha frames");
  if (flows.size() != alphas.size())
    throw ValueError(concat(alphas.size(), " target alpha frames but ", flows.size(), " flow frames"));
  const std::size_t n = alphas.size(), m = exemplar.size();
  std::vector<Image> raw, out;
  OffsetField previous_field;
  for (std::size_t t = 0; t < n; ++t) {
    require_same_size(alphas[t], concat("target alpha ", t).c_str(), flows[t], concat("flow ", t).c_str());
    FluidFrameInput in;
    in.style = exemplar[t % m];
    in.previous_style = t == 0 ? in.style : exemplar[(t - 1) % m];
    in.target_alpha = alphas[t];
    const Image advected = t == 0 ? Image() : advect_output(raw.back().view(), flows[t - 1]);
    in.advected = advected.empty() ? ImageView{} : advected.view();
    if (t > 0) in.previous_field = &previous_field, in.flow_previous = flows[t - 1];
    auto report = [&](double f) { return !progress || progress((double(t) + f) / double(n)); };
    FluidFrameResult frame = stylize_fluid_frame(in, o, report);
    previous_field = std::move(frame.synthesis.field);
    raw.push_back(std::move(frame.image));
    out.push_back(motion_blur_along_flow(raw.back().view(), flows[t], o.motion_blur));
  }
  return out;
}

}  // namespace tempera

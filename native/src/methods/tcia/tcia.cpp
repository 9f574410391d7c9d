#include "tempera/methods/tcia/tcia.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "tempera/engine/error.hpp"
#include "tempera/engine/motion.hpp"
#include "tempera/engine/rng.hpp"
#include "tempera/engine/solver.hpp"
#include "tempera/methods/tcia/tcia_derivative.hpp"
#include "tempera/methods/tcia/tcia_ribbons.hpp"

namespace tempera {

SynthesisOptions tcia_defaults() {
  SynthesisOptions o;
  o.patch_size = 9;
  o.window_sigma = 3.0f;
  o.output = OutputMode::Centre;
  o.usage = PatchUsage::Histogram;
  o.levels = 0;  // automatic: the coarsest side >= 4 patches (4 levels at 0.25 Mpix, 5 at 1 Mpix)
  o.em_iterations = 1;
  o.pm_iterations = 4;  // "3 or 4 full iterations" of parallel PatchMatch (§3.3)
  o.guide_variance = 1.0;
  // Each visit starts from the advected and upsampled matches: past its
  // first sweep, the random search stays within 64 px of them (issue 32,
  // step 34): 0.87-0.95x the time on bench_shots' shots at 1-2 Mpix; on a
  // real shot, warp error +0.5-0.9% and detail +0.3-0.5% over three seeds.
  o.search_radius = 64;
  // Eq. 8's h_s, h_tau and blur, which the paper does not give, measured for
  // this schedule (one search per visit, centre output) on the hotspot shot of
  // tests/cpp/test_tcia.cpp: the blurred usage peak drops 2.6x for 1.07x the
  // energy. The engine's defaults (1, 2, 1.5) drop it 3.6x for 1.3x there.
  o.histogram_weight = 0.2f;
  o.histogram_threshold = 4.0f;
  o.histogram_sigma = 3.0f;
  return o;
}

Image pick_resize(const ImageView& image, int width, int height, float scale) {
  Image out(width, height, image.channels);
  for (int y = 0; y < height; ++y) {
    const int sy = std::min(image.height - 1, int((y + 0.5) * image.height / height));
    for (int x = 0; x < width; ++x) {
      const int sx = std::min(image.width - 1, int((x + 0.5) * image.width / width));
      for (int c = 0; c < image.channels; ++c) out.at(x, y, c) = scale * image.at(sx, sy, c);
    }
  }
  return out;
}

namespace {

// `image` with `m` pixels of edge-replicated border on each side.
Image pad(const ImageView& image, int m) {
  Image out(image.width + 2 * m, image.height + 2 * m, image.channels);
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) {
      const float* p = image.pixel(std::clamp(x - m, 0, image.width - 1), std::clamp(y - m, 0, image.height - 1));
      std::copy_n(p, image.channels, out.pixel(x, y));
    }
  return out;
}

void validate(const Shot& shot, const TciaOptions& o) {
  require_nonempty(shot.style, "style");
  if (shot.frames.empty()) throw ValueError("the shot has no frames");
  const std::size_t layers = shot.style_guides.size();
  if (shot.guide_names.size() != layers || shot.guide_weights.size() != layers)
    throw ValueError("each exemplar guide needs a name and a weight");
  for (std::size_t t = 0; t < shot.frames.size(); ++t) {
    const ShotFrame& f = shot.frames[t];
    if (f.guides.size() != layers)
      throw ValueError(concat("frame ", t, " has ", f.guides.size(), " guides for ", layers, " exemplar guides"));
    for (const ImageView* v : {&f.velocity_backward, &f.velocity_forward})
      if (v->channels != 2) throw ValueError(concat("frame ", t, ": velocities must have 2 channels"));
    for (const ImageView* v : {&f.occlusion_backward, &f.occlusion_forward})
      if (v->channels != 1) throw ValueError(concat("frame ", t, ": occlusions must have 1 channel"));
    if (f.orientation.empty() != shot.style_orientation.empty())
      throw ValueError(concat("frame ", t, shot.style_orientation.empty() ? " has an orientation but the style has none"
                                                                         : " has no orientation but the style has one"));
  }
  int last = -1;
  for (const ShotKey& k : shot.keys) {
    if (k.frame <= last || k.frame >= int(shot.frames.size()))
      throw ValueError(concat("keyframe ", k.frame, " is outside the shot or out of order"));
    last = k.frame;
    require_nonempty(k.painting, concat("the painting of keyframe ", k.frame));
    if (k.painting.channels != shot.style.channels)
      throw ValueError(concat("the painting of keyframe ", k.frame, " has ", k.painting.channels,
                              " channels, the style ", shot.style.channels));
    // Named here: the solver would only see "exemplar 1 mask" (a key is an extra exemplar there).
    if (!k.mask.empty() && std::none_of(k.mask.data, k.mask.data + k.mask.size(), [](float v) { return v > 0.5f; }))
      throw ValueError(concat("the mask of keyframe ", k.frame,
                              " is empty (nothing above 0.5): paint white where the key holds, or give no mask "
                              "for the whole frame"));
  }
  validate_fields(o, tcia_option_table());
  validate(o.synthesis);
}

// Per frame and level: what the sweeps keep.
struct FrameState {
  std::optional<OffsetField> field;
  Image image;
};

class Sweeper {
 public:
  Sweeper(const Shot& shot, const TciaOptions& o) : shot_(shot), o_(o) {
    if (o.ribbons && !shot.keys.empty()) ribbons_ = trace_ribbons(shot);
  }

  std::vector<Image> run(const SweepCallback& progress) {
    const int frames = int(shot_.frames.size());
    const int levels = make_solver(0, false)->levels();
    std::vector<FrameState> coarse, here(frames);
    const double visits = double(levels) * 2 * o_.sweep_pairs * frames;
    double done = 0;
    auto report = [&](int l, int pair, int direction, int t) {
      if (progress && !progress({l, levels, pair, o_.sweep_pairs, direction, t, ++done / visits}))
        throw CancelledError("stylization cancelled");
    };
    for (int l = levels - 1; l >= 0; --l) {
      for (int pair = 0; pair < o_.sweep_pairs; ++pair) {
        for (int t = 0; t < frames; ++t) visit(l, t, +1, pair, coarse, here), report(l, pair, +1, t);
        for (int t = frames - 1; t >= 0; --t) visit(l, t, -1, pair, coarse, here), report(l, pair, -1, t);
      }
      coarse = std::move(here);
      here.assign(frames, {});
    }
    std::vector<Image> out;
    for (auto& s : coarse) out.push_back(std::move(s.image));
    return out;
  }

 private:
  // The solver of frame t, with the temporal guide when `temporal` (its
  // target is given per level; the input's is a placeholder).
  std::unique_ptr<Solver> make_solver(int t, bool temporal, int direction = +1) const {
    const ShotFrame& f = shot_.frames[std::size_t(t)];
    // A shot without guides (keys and motion only) takes the frame's size from its motion.
    const ImageView& sized = f.guides.empty() ? f.velocity_backward : f.guides[0];
    placeholder_ = Image(sized.width, sized.height, shot_.style.channels);
    SynthesisInput in;
    in.style = shot_.style;
    in.source_mask = shot_.style_mask;
    in.source_orientation = shot_.style_orientation;
    in.target_orientation = f.orientation;
    for (std::size_t g = 0; g < shot_.style_guides.size(); ++g)
      in.guides.add(shot_.guide_names[g], shot_.style_guides[g], f.guides[g], shot_.guide_weights[g]);
    if (in.guides.empty()) {
      in.target_width = placeholder_.width();
      in.target_height = placeholder_.height();
    }
    if (temporal && o_.temporal_weight > 0) {
      in.target_weight_maps.assign(in.guides.layers().size(), ImageView{});
      in.guides.add("temporal", shot_.style, placeholder_.view(), o_.temporal_weight);
      in.target_weight_maps.push_back(direction > 0 ? f.occlusion_backward : f.occlusion_forward);
    }
    if (temporal && derivative()) {
      in.target_weight_maps.resize(in.guides.layers().size());
      derivative_placeholders_.clear();
      derivative_placeholders_.reserve(shot_.style_guides.size());
      for (std::size_t g = 0; g < shot_.style_guides.size(); ++g) {
        const Image& target = derivative_placeholders_.emplace_back(sized.width, sized.height, f.guides[g].channels);
        in.guides.add("derivative_" + shot_.guide_names[g], shot_.style_guides[g], target.view(),
                      o_.derivative_weight * shot_.guide_weights[g]);
        in.target_weight_maps.push_back(direction > 0 ? f.occlusion_backward : f.occlusion_forward);
      }
    }
    // Keys: extra exemplars (the painting over its frame's guides) and, at
    // their own frame, the painted pixels fixed to the painting. A key is
    // padded by the patch margin (edge pixels repeated, not copyable), so
    // that its border pixels can be patch centres: in-betweens can then copy
    // a key right up to the frame's edge.
    const int m = key_padding();
    keys_.clear();
    keys_.reserve(shot_.keys.size());
    for (std::size_t k = 0; k < shot_.keys.size(); ++k) {
      const ShotKey& key = shot_.keys[k];
      PaddedKey& pk = keys_.emplace_back();
      pk.painting = pad(key.painting, m);
      const ShotFrame& kf = shot_.frames[std::size_t(key.frame)];
      for (const ImageView& g : kf.guides) pk.guides.push_back(pad(g, m));
      if (!kf.orientation.empty()) pk.orientation = pad(kf.orientation, m);
      pk.mask = Image(pk.painting.width(), pk.painting.height(), 1);
      for (int y = 0; y < key.painting.height; ++y)
        for (int x = 0; x < key.painting.width; ++x)
          pk.mask.at(x + m, y + m, 0) = key.mask.empty() ? 1.0f : key.mask.at(x, y, 0);
      Exemplar e;
      e.style = pk.painting.view();
      for (const Image& g : pk.guides) e.guides.push_back(g.view());
      if (temporal && o_.temporal_weight > 0) e.guides.push_back(pk.painting.view());
      if (temporal && derivative())
        for (const Image& g : pk.guides) e.guides.push_back(g.view());
      e.mask = pk.mask.view();
      if (!pk.orientation.empty()) e.orientation = pk.orientation.view();
      in.exemplars.push_back(e);
      if (key.frame == t) {
        key_mask_ = key.mask.empty() ? Image(key.painting.width, key.painting.height, 1, 1.0f) : Image::copy_of(key.mask);
        key_matches_ = Image(key.painting.width, key.painting.height, 3);
        for (int y = 0; y < key.painting.height; ++y)
          for (int x = 0; x < key.painting.width; ++x) {
            float* match = key_matches_.pixel(x, y);
            match[0] = float(k + 1), match[1] = float(x + m), match[2] = float(y + m);
          }
        in.fixed = FixedPixels{key_mask_.view(), key.painting, key_matches_.view()};
      }
    }
    if (o_.coherence_weight > 0) in.terms.push_back(make_spatial_coherence(o_.coherence_weight, o_.coherence_max));
    SynthesisOptions opt = o_.synthesis;
    opt.seed = mix64(o_.synthesis.seed ^ mix64(std::uint64_t(t) + 0x7C1Aull));
    return std::make_unique<Solver>(in, opt);
  }

  // The keys' border: the patch radius, or with orientations the radius of a
  // patch turned 45 degrees (PatchSpace::source_margin), so that every key
  // pixel can be a patch centre.
  int key_padding() const {
    const int r = o_.synthesis.patch_size / 2;
    return shot_.style_orientation.empty() ? r : int(std::ceil(r * 1.41421356f)) + 1;
  }

  // Eq. 10 (tcia_derivative.hpp): with keys and a derivative weight.
  bool derivative() const {
    return o_.derivative_weight > 0 && !shot_.keys.empty() && !shot_.style_guides.empty();
  }

  // Eq. 10's target per guide layer for frame t at level l, from the
  // neighbour frame `from` (solved, with `field`) and the level's V.
  std::vector<Image> level_derivative_targets(const Solver& solver, int l, int t, int from, const OffsetField& field,
                                              const Image& v) const {
    const int w = v.width(), h = v.height();
    std::vector<Image> out;
    for (std::size_t g = 0; g < shot_.style_guides.size(); ++g) {
      std::vector<ImageView> exemplar_guides{shot_.style_guides[g]};
      for (const PaddedKey& k : keys_) exemplar_guides.push_back(k.guides[g].view());
      out.push_back(derivative_target(pick_resize(shot_.frames[std::size_t(t)].guides[g], w, h),
                                      pick_resize(shot_.frames[std::size_t(from)].guides[g], w, h),
                                      matched_guide(solver, l, field, exemplar_guides), v.view()));
    }
    return out;
  }

  // Frame t's V (backward for forward sweeps, minus V+ for backward ones, so
  // that "p came from p - V" holds either way) and χ at level size.
  Image level_velocity(int t, int direction, int w, int h) const {
    const ShotFrame& f = shot_.frames[std::size_t(t)];
    const ImageView& v = direction > 0 ? f.velocity_backward : f.velocity_forward;
    return pick_resize(v, w, h, float(direction > 0 ? 1 : -1) * float(w) / float(v.width));
  }
  Image level_visibility(int t, int direction, int w, int h) const {
    const ShotFrame& f = shot_.frames[std::size_t(t)];
    return pick_resize(direction > 0 ? f.occlusion_backward : f.occlusion_forward, w, h);
  }

  void visit(int l, int t, int direction, int pair, std::vector<FrameState>& coarse,
             std::vector<FrameState>& here) {
    const int frames = int(shot_.frames.size()), from = t - direction;
    // The neighbour in sweep order, solved at this level already (forward
    // sweeps fill the frames in order, backward ones re-solve them in reverse).
    const bool neighbour_in_sweep = from >= 0 && from < frames && here[std::size_t(from)].field.has_value();
    const auto solver = make_solver(t, neighbour_in_sweep, direction);
    const int w = solver->target_width(l), h = solver->target_height(l);
    FrameState& state = here[std::size_t(t)];
    // The frame's own previous solution: this level's (an earlier sweep) or
    // the coarser level's, upsampled.
    std::optional<OffsetField> own;
    if (state.field) own = *state.field;
    else if (!coarse.empty() && coarse[std::size_t(t)].field) {
      own = solver->resample(*coarse[std::size_t(t)].field, l + 1, l);
      coarse[std::size_t(t)] = FrameState{};  // read only at this first visit: freed, not held through the level
    }
    std::optional<OffsetField> advected;
    Image visible, temporal_target;
    Image v_level;
    if (neighbour_in_sweep) {
      v_level = level_velocity(t, direction, w, h);
      const Image& v = v_level;
      visible = level_visibility(t, direction, w, h);
      advected = solver->advect(*here[std::size_t(from)].field, l, v.view());
      temporal_target = warp_backward(here[std::size_t(from)].image.view(), v.view());
    }
    LevelStart start;
    OffsetField merged;
    if (advected && own) {
      merged = *own;
      Rng rng(o_.synthesis.seed, mix64(std::uint64_t(l) * 7919 + std::uint64_t(t) * 131 + std::uint64_t(direction + 1) +
                                       std::uint64_t(pair) * 1000003ull));
      const std::uint64_t share = std::uint64_t(advected_share(t, direction) * 4294967296.0);
      for (std::size_t i = 0; i < merged.x.size(); ++i) {
        // Fig. 7's random merge; where the neighbour does not see p, p's own.
        if (visible.data()[i] > 0.5f && (rng.next() >> 32) < share) {
          merged.x[i] = advected->x[i], merged.y[i] = advected->y[i];
          merged.rx[i] = advected->rx[i], merged.ry[i] = advected->ry[i];
        }
      }
      start.field = &merged;
    } else if (advected) {
      // The coarsest level's first visit of a frame: disoccluded pixels get
      // a random source (legalize_field relocates out-of-range positions).
      merged = *advected;
      for (std::size_t i = 0; i < merged.x.size(); ++i)
        if (visible.data()[i] <= 0.5f) merged.x[i] = -1;
      start.field = &merged;
    } else if (own) {
      start.field = &*own;
    }
    CandidateList ribbons;
    if (!ribbons_.empty()) {
      ribbons = ribbon_candidates(ribbons_[std::size_t(t)], *solver, l, key_padding());
      start.candidates = &ribbons;
    }
    if (neighbour_in_sweep && o_.temporal_weight > 0)
      start.guide_targets.emplace_back(int(shot_.style_guides.size()), &temporal_target);
    std::vector<Image> derivative_targets;
    if (neighbour_in_sweep && derivative()) {
      const int first = int(shot_.style_guides.size()) + (o_.temporal_weight > 0 ? 1 : 0);
      derivative_targets = level_derivative_targets(*solver, l, t, from, *here[std::size_t(from)].field, v_level);
      for (std::size_t g = 0; g < derivative_targets.size(); ++g)
        start.guide_targets.emplace_back(first + int(g), &derivative_targets[g]);
    }
    LevelResult r = solver->solve_level(l, start);
    state.field = std::move(r.field);
    state.image = std::move(r.image);
  }

  const Shot& shot_;
  const TciaOptions& o_;
  std::vector<FrameRibbons> ribbons_;  // per frame; empty without keys or with ribbons off
  mutable Image placeholder_;  // full-size stand-in target of the temporal guide
  mutable std::vector<Image> derivative_placeholders_;  // and of eq. 10's, per guide layer
  mutable Image key_mask_, key_matches_;  // the fixed pixels of a key frame
  struct PaddedKey {
    Image painting, mask, orientation;
    std::vector<Image> guides;
  };
  mutable std::vector<PaddedKey> keys_;  // the keys as exemplars of the solver being built

  // Probability that the merge takes the advected neighbour at frame t: 1/2,
  // or between keys t_l < t < t_n, (t_n - t) / (t_n - t_l) forward and
  // (t - t_l) / (t_n - t_l) backward, so each key's influence fades with
  // distance (§4.1).
  double advected_share(int t, int direction) const {
    int before = -1, after = -1;
    for (const ShotKey& k : shot_.keys) {
      if (k.frame < t) before = k.frame;
      if (k.frame > t && after < 0) after = k.frame;
    }
    if (before < 0 || after < 0) return 0.5;
    const double span = after - before;
    return direction > 0 ? (after - t) / span : (t - before) / span;
  }
};

}  // namespace

std::vector<Image> stylize_shot_sweeps(const Shot& shot, const TciaOptions& options, const SweepCallback& progress) {
  validate(shot, options);
  return Sweeper(shot, options).run(progress);
}

std::vector<Image> stylize_shot(const Shot& shot, const TciaOptions& options, const ProgressCallback& progress) {
  SweepCallback sweeps;
  if (progress) sweeps = [&](const SweepProgress& p) { return progress(p.fraction); };
  return stylize_shot_sweeps(shot, options, sweeps);
}

}  // namespace tempera

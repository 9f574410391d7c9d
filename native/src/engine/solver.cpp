#include "tempera/engine/solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <tuple>

#include "tempera/engine/color.hpp"
#include "tempera/engine/converged_pixels.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/engine/guide_compression.hpp"
#include "tempera/engine/patch_usage.hpp"
#include "tempera/engine/pyramid.hpp"
#include "tempera/engine/voting.hpp"

namespace tempera {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void source_indices(const OffsetField& field, int source_width, std::vector<std::int32_t>& out) {
  out.resize(field.x.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = field.y[i] * source_width + field.x[i];
}

// ---- inputs ----

// The exemplars of the source set: `style` first, then `exemplars`, each with
// its guides in layer order.
std::vector<Exemplar> all_exemplars(const SynthesisInput& in) {
  std::vector<Exemplar> out;
  Exemplar primary;
  primary.style = in.style;
  for (const auto& layer : in.guides.layers()) primary.guides.push_back(layer.source);
  primary.mask = in.source_mask;
  primary.orientation = in.source_orientation;
  primary.segments = in.source_segments;
  primary.sequence = in.sequence;
  primary.time = in.time;
  out.push_back(primary);
  out.insert(out.end(), in.exemplars.begin(), in.exemplars.end());
  return out;
}

int target_width_of(const SynthesisInput& in) { return in.guides.empty() ? in.target_width : in.guides.target_width(); }
int target_height_of(const SynthesisInput& in) {
  return in.guides.empty() ? in.target_height : in.guides.target_height();
}

void check_map(const ImageView& map, const std::string& what, int w, int h, const char* of) {
  if (map.empty()) return;
  if (map.channels != 1) throw ValueError(concat(what, " must have 1 channel, got ", map.channels));
  if (map.width != w || map.height != h)
    throw ValueError(concat(what, " is ", map.width, "x", map.height, " but the ", of, " is ", w, "x", h));
  require_finite(map, what);
}

bool any_inside(const ImageView& m) {
  for (std::size_t i = 0; i < m.size(); ++i)
    if (m.data[i] > 0.5f) return true;
  return false;
}

void check_labels(const ImageView& labels) {
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (labels.data[i] < 0 || labels.data[i] > 65535) throw ValueError("segment labels must be integers in [0, 65535]");
}

void validate_exemplar(const Exemplar& e, const std::string& what, const SynthesisInput& in) {
  require_nonempty(e.style, what);
  require_finite(e.style, what);
  if (e.style.channels != in.style.channels)
    throw ValueError(concat(what, " has ", e.style.channels, " channels but the style has ", in.style.channels));
  const auto& layers = in.guides.layers();
  if (e.guides.size() != layers.size())
    throw ValueError(concat(what, " has ", e.guides.size(), " guides for ", layers.size(), " guide layers"));
  for (std::size_t g = 0; g < layers.size(); ++g) {
    const std::string gw = concat(what, " guide '", layers[g].name, "'");
    require_same_size(e.guides[g], gw, e.style, what);
    if (e.guides[g].channels != layers[g].source.channels)
      throw ValueError(concat(gw, " has ", e.guides[g].channels, " channels, the layer has ", layers[g].source.channels));
    require_finite(e.guides[g], gw);
  }
  check_map(e.mask, what + " mask", e.style.width, e.style.height, what.c_str());
  check_map(e.orientation, what + " orientation", e.style.width, e.style.height, what.c_str());
  check_map(e.segments, what + " segments", e.style.width, e.style.height, what.c_str());
  if (!e.mask.empty() && !any_inside(e.mask)) throw ValueError(what + " mask is empty");
  check_labels(e.segments);
}

void validate_input(const SynthesisInput& in) {
  require_nonempty(in.style, "style");
  require_finite(in.style, "style");
  if (!in.guides.empty()) {
    require_same_size(in.guides.layers().front().source, "guide source", in.style, "style");
  } else if (in.target_width <= 0 || in.target_height <= 0) {
    throw ValueError("without guides the target size must be given");
  }
  const int tw = target_width_of(in), th = target_height_of(in);
  check_map(in.source_mask, "source mask", in.style.width, in.style.height, "style");
  check_map(in.target_mask, "target mask", tw, th, "target");
  check_map(in.source_orientation, "source orientation", in.style.width, in.style.height, "style");
  check_map(in.target_orientation, "target orientation", tw, th, "target");
  check_map(in.source_segments, "source segments", in.style.width, in.style.height, "style");
  check_map(in.target_segments, "target segments", tw, th, "target");
  for (const auto& map : in.target_weight_maps) check_map(map, "target weight map", tw, th, "target");
  if (in.target_weight_maps.size() > in.guides.layers().size())
    throw ValueError(concat(in.target_weight_maps.size(), " target weight maps for ", in.guides.layers().size(),
                            " guides"));
  if (!in.source_mask.empty() && !any_inside(in.source_mask)) throw ValueError("source mask is empty");
  if (!in.target_mask.empty() && !any_inside(in.target_mask)) throw ValueError("target mask is empty");
  check_labels(in.source_segments);
  check_labels(in.target_segments);
  for (std::size_t k = 0; k < in.exemplars.size(); ++k) validate_exemplar(in.exemplars[k], concat("exemplar ", k + 1), in);
  if (in.style.channels + in.guides.total_channels() > 248)
    throw ValueError(concat("too many channels (", in.style.channels + in.guides.total_channels(),
                            "); at most 248 style and guide channels are supported"));
  auto check_target_image = [&](const ImageView& image, const char* what) {
    if (image.empty()) return;
    if (image.width != tw || image.height != th)
      throw ValueError(concat(what, " is ", image.width, "x", image.height, " but the target is ", tw, "x", th));
    if (image.channels != in.style.channels)
      throw ValueError(concat(what, " has ", image.channels, " channels, the style ", in.style.channels));
    require_finite(image, what);
  };
  check_target_image(in.reference, "reference");
  if (!in.fixed.empty()) {
    check_map(in.fixed.mask, "fixed-pixel mask", tw, th, "target");
    check_target_image(in.fixed.values, "fixed-pixel values");
    if (in.fixed.values.empty()) throw ValueError("fixed pixels need their values");
    if (!in.fixed.matches.empty()) {
      if (in.fixed.matches.channels != 3 || in.fixed.matches.width != tw || in.fixed.matches.height != th)
        throw ValueError(concat("fixed-pixel matches must be ", tw, "x", th, " with 3 channels (exemplar, x, y)"));
      const int n = int(in.exemplars.size()) + 1;
      for (std::size_t i = 0; i < in.fixed.matches.pixel_count(); ++i) {
        const float e = in.fixed.matches.data[3 * i];
        if (in.fixed.mask.data[i] > 0.5f && !(e >= 0 && e < n && e == std::floor(e)))
          throw ValueError(concat("fixed-pixel match names exemplar ", e, "; there are ", n));
      }
    }
  }
}

// ---- pyramids ----

// The channels of `parts` side by side.
Image stack_channels(const std::vector<ImageView>& parts) {
  int channels = 0;
  for (const auto& p : parts) channels += p.channels;
  Image out(parts.front().width, parts.front().height, channels);
  const std::size_t n = out.pixel_count();
  int first = 0;
  for (const ImageView& p : parts) {
    for (std::size_t i = 0; i < n; ++i)
      std::memcpy(out.data() + i * channels + first, p.data + i * p.channels, sizeof(float) * p.channels);
    first += p.channels;
  }
  return out;
}

// Angles downsample as unit vectors (averaging raw angles breaks at the
// wrap-around); axial angles as doubled-angle vectors, so a and a + pi agree.
std::vector<Image> angle_pyramid(const ImageView& angles, int levels, double ratio, bool axial) {
  const float k = axial ? 2.0f : 1.0f;
  Image vec(angles.width, angles.height, 2);
  for (std::size_t i = 0; i < angles.pixel_count(); ++i) {
    vec.data()[2 * i] = std::cos(k * angles.data[i]);
    vec.data()[2 * i + 1] = std::sin(k * angles.data[i]);
  }
  std::vector<Image> out;
  for (auto& level : build_pyramid(vec.view(), levels, ratio, {})) {
    Image a(level.width(), level.height(), 1);
    for (std::size_t i = 0; i < a.pixel_count(); ++i)
      a.data()[i] = std::atan2(level.data()[2 * i + 1], level.data()[2 * i]) / k;
    out.push_back(std::move(a));
  }
  return out;
}

// Labels downsample by picking (no blending of unrelated labels): level l's
// pixel x takes level 0's pixel x / ratio^l.
std::vector<Image> label_pyramid(const ImageView& labels, int levels, double ratio) {
  std::vector<Image> out;
  const auto sizes = level_sizes(labels.width, labels.height, levels, ratio);
  for (int l = 0; l < levels; ++l) {
    const auto [w, h] = sizes[l];
    const double scale = std::pow(1.0 / ratio, l);
    Image next(w, h, 1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        next.at(x, y, 0) = labels.at(std::min(labels.width - 1, int(x * scale)), std::min(labels.height - 1, int(y * scale)), 0);
    out.push_back(std::move(next));
  }
  return out;
}

std::vector<Image> constant_pyramid(int w, int h, int levels, double ratio, float value) {
  std::vector<Image> out;
  for (const auto& [lw, lh] : level_sizes(w, h, levels, ratio)) out.emplace_back(lw, lh, 1, value);
  return out;
}

// Per level: the exemplars' pyramids of one map stacked into the atlas.
// Exemplars without the map get `fill`.
template <class PyramidOf>
std::vector<Image> atlas_pyramid(const std::vector<Exemplar>& ex, const std::vector<SourceLayout>& layouts,
                                 const ImageView Exemplar::*member, int levels, double ratio, float fill,
                                 PyramidOf pyramid_of) {
  const bool any = std::any_of(ex.begin(), ex.end(), [&](const Exemplar& e) { return !(e.*member).empty(); });
  if (!any) return {};
  std::vector<std::vector<Image>> per;
  for (const auto& e : ex)
    per.push_back((e.*member).empty() ? constant_pyramid(e.style.width, e.style.height, levels, ratio, fill)
                                      : pyramid_of(e.*member));
  std::vector<Image> out;
  for (int l = 0; l < levels; ++l) {
    std::vector<Image> parts;
    for (auto& p : per) parts.push_back(std::move(p[l]));
    out.push_back(stack_atlas(std::move(parts), layouts[l]));
  }
  return out;
}

Image gaussian_window(int radius, float sigma) {
  const int side = 2 * radius + 1;
  Image w(side, side, 1);
  double sum = 0;
  for (int y = -radius; y <= radius; ++y)
    for (int x = -radius; x <= radius; ++x) sum += w.at(x + radius, y + radius, 0) = std::exp(-0.5f * (x * x + y * y) / (sigma * sigma));
  for (std::size_t i = 0; i < w.pixel_count(); ++i) w.data()[i] = float(w.data()[i] * side * side / sum);  // mean 1
  return w;
}

}  // namespace

// Everything the engine derives from the inputs once, for all levels.
struct Solver::Plan {
  int levels = 0;
  double ratio = 0.5;
  int style_channels = 0;
  std::vector<int> guide_channels;  // per guide layer of the plan: the input's, or the PCA-merged ones as one
  std::vector<float> guide_weights;  // per guide layer of the input
  int merged_layers = 0;  // the input's leading layers merged into the plan's layer 0 by PCA (0: none)
  // The plan's layer of an input layer past the merged ones.
  int plan_layer(int input_layer) const { return merged_layers ? input_layer - merged_layers + 1 : input_layer; }
  double kept_variance = 1.0;
  std::vector<SourceLayout> layout;   // per level
  std::vector<Image> source, target;  // source: style + guides (atlas); target: guides
  // Per level: the sizes of `source` and `target`, which outlive them once a
  // level's last solve has freed them (LevelStart::last_use).
  std::vector<std::pair<int, int>> source_size, target_size;
  std::vector<Image> source_mask, target_mask, source_angle, target_angle, source_label, target_label;
  std::vector<std::vector<Image>> weight_maps;  // per guide (may be empty)
  std::vector<Image> reference, fixed_mask, fixed_values;
  std::vector<OffsetField> fixed_field;  // per level; empty when the fixed pixels have no matches
  std::vector<float> style_scales;       // sqrt of the style weight per style channel
  Image window;                          // Gaussian patch window, or empty
};

// One pyramid level: features, constraints and the patch space over them.
struct Solver::Level {
  FeatureImage source, target, target_weights;
  std::vector<std::uint8_t> weighted_pixels, weighted_patches;  // PatchSpace's, with quantized weighted features
  std::vector<float> window_channels;                           // PatchSpace's, with a window
  SearchConstraints constraints;
  PatchSpace space;
  Image style;          // A' at this level (unweighted), what voting copies
  std::vector<std::uint8_t> fixed, voters;  // hard-constrained pixels; pixels whose patches vote
};

void validate(const SynthesisOptions& opt) {
  validate_fields(opt, synthesis_option_table());
  if (opt.patch_size % 2 == 0) throw ValueError(concat("patch size must be odd and >= 3, got ", opt.patch_size));
}

Solver::Solver(const SynthesisInput& in, const SynthesisOptions& opt) : plan_(new Plan), options_(opt) {
  validate(opt);
  validate_input(in);
  Plan& p = *plan_;
  const std::vector<Exemplar> ex = all_exemplars(in);
  const int tw = target_width_of(in), th = target_height_of(in);
  const int min_side = 4 * opt.patch_size;
  int auto_levels = pyramid_levels_for(tw, th, min_side, 12, opt.level_ratio);
  for (const auto& e : ex)
    auto_levels = std::min(auto_levels, pyramid_levels_for(e.style.width, e.style.height, min_side, 12, opt.level_ratio));
  p.levels = opt.levels > 0 ? opt.levels : auto_levels;
  p.ratio = opt.level_ratio;
  p.style_channels = in.style.channels;

  // Guides are scaled by sqrt(weight) once here; after that every feature
  // channel but the style's has weight 1.
  const auto& layers = in.guides.layers();
  std::vector<Image> src_guides(ex.size());  // per exemplar, all layers stacked along channels
  Image tgt_guides;
  if (!layers.empty()) {
    std::vector<WeightedGuides> sources(ex.size());
    WeightedGuides target;
    for (const auto& layer : layers) {
      target.scales.push_back(std::sqrt(layer.weight));
      target.layers.push_back(layer.target);
      p.guide_channels.push_back(layer.source.channels);
      p.guide_weights.push_back(layer.weight);
    }
    for (std::size_t e = 0; e < ex.size(); ++e) sources[e] = {ex[e].guides, target.scales};
    // The leading layers without a weight map are merged by PCA; a layer
    // with a map (and every one after it) keeps its channels, so that its
    // map weighs them alone (StyLit's temporal guide, weighed by χ-).
    std::size_t merged = 0;
    while (merged < layers.size() && (merged >= in.target_weight_maps.size() || in.target_weight_maps[merged].empty()))
      ++merged;
    const auto leading = [merged](const WeightedGuides& g) {
      return WeightedGuides{{g.layers.begin(), g.layers.begin() + std::ptrdiff_t(merged)},
                            {g.scales.begin(), g.scales.begin() + std::ptrdiff_t(merged)}};
    };
    // The projected channels, then the stacked channels of the layers after the merged ones.
    const auto with_rest = [merged, &layers](Image projected, const WeightedGuides& g) {
      if (merged == layers.size()) return projected;
      const WeightedGuides rest{{g.layers.begin() + std::ptrdiff_t(merged), g.layers.end()},
                                {g.scales.begin() + std::ptrdiff_t(merged), g.scales.end()}};
      return stack_channels({projected.view(), rest.stacked().view()});
    };
    if (opt.guide_variance < 1.0 && merged > 0 && leading(target).channels() > 1) {
      // One projection for the whole source set, fitted on all of it and
      // applied to the layers in place (no stacked copy).
      std::vector<WeightedGuides> lead(ex.size());
      for (std::size_t e = 0; e < ex.size(); ++e) lead[e] = leading(sources[e]);
      const GuideProjection proj = fit_guide_projection(lead, leading(target), opt.guide_variance);
      for (std::size_t e = 0; e < ex.size(); ++e) src_guides[e] = with_rest(proj.apply(lead[e]), sources[e]);
      if (in.exemplar_guides_read) in.exemplar_guides_read();
      tgt_guides = with_rest(proj.apply(leading(target)), target);
      p.guide_channels.erase(p.guide_channels.begin(), p.guide_channels.begin() + std::ptrdiff_t(merged));
      p.guide_channels.insert(p.guide_channels.begin(), proj.output_channels());
      p.merged_layers = int(merged);
      p.kept_variance = proj.kept_variance;
    } else {
      for (std::size_t e = 0; e < ex.size(); ++e) src_guides[e] = sources[e].stacked();
      if (in.exemplar_guides_read) in.exemplar_guides_read();
      tgt_guides = target.stacked();
    }
  }
  // The guide layers are not read past this point.
  if (in.guides_read) in.guides_read();

  // The atlas of each level.
  std::vector<std::vector<std::pair<int, int>>> sizes;  // per exemplar, per level
  std::vector<int> sequence, time;
  for (const auto& e : ex) {
    sizes.push_back(level_sizes(e.style.width, e.style.height, p.levels, p.ratio));
    sequence.push_back(e.sequence);
    time.push_back(e.time);
  }
  for (int l = 0; l < p.levels; ++l) {
    std::vector<std::pair<int, int>> at;
    for (const auto& s : sizes) at.push_back(s[l]);
    p.layout.push_back(SourceLayout::stack(at, sequence, time));
  }
  {
    std::vector<std::vector<Image>> per;
    for (std::size_t e = 0; e < ex.size(); ++e) {
      if (src_guides[e].empty()) {
        per.push_back(build_pyramid(ex[e].style, p.levels, p.ratio, opt.level_box_widths));
        continue;
      }
      Image stacked = stack_channels({ex[e].style, src_guides[e].view()});
      src_guides[e] = Image();
      per.push_back(build_pyramid(std::move(stacked), p.levels, p.ratio, opt.level_box_widths));
    }
    for (int l = 0; l < p.levels; ++l) {
      std::vector<Image> parts;
      for (auto& pyr : per) parts.push_back(std::move(pyr[l]));
      p.source.push_back(stack_atlas(std::move(parts), p.layout[l]));
    }
  }
  if (!tgt_guides.empty()) {
    p.target = build_pyramid(std::move(tgt_guides), p.levels, p.ratio, opt.level_box_widths);
  } else {
    for (const auto& [w, h] : level_sizes(tw, th, p.levels, p.ratio)) p.target.emplace_back(w, h, 1);
  }
  for (int l = 0; l < p.levels; ++l) {
    p.source_size.emplace_back(p.source[l].width(), p.source[l].height());
    p.target_size.emplace_back(p.target[l].width(), p.target[l].height());
  }
  for (std::size_t e = 0; e < ex.size(); ++e) {
    const auto [cw, ch] = sizes[e].back();
    if (cw >= opt.patch_size + 2 && ch >= opt.patch_size + 2) continue;
    const std::string what = e == 0 ? std::string("the style") : concat("exemplar ", e);
    if (p.levels == 1)
      throw ValueError(concat(what, " is ", ex[e].style.width, "x", ex[e].style.height, " pixels; patch size ",
                              opt.patch_size, " needs at least ", opt.patch_size + 2, "x", opt.patch_size + 2));
    throw ValueError(concat(what, " (", ex[e].style.width, "x", ex[e].style.height, ") is too small for ", p.levels,
                            " pyramid levels with patch size ", opt.patch_size,
                            "; use fewer levels (0 = automatic) or a larger exemplar"));
  }
  const int L = p.levels;
  const double r = p.ratio;
  auto plain = [&](const ImageView& m) { return build_pyramid(m, L, r, {}); };
  p.source_mask = atlas_pyramid(ex, p.layout, &Exemplar::mask, L, r, 1.0f, plain);
  p.source_angle = atlas_pyramid(ex, p.layout, &Exemplar::orientation, L, r, 0.0f,
                                 [&](const ImageView& a) { return angle_pyramid(a, L, r, opt.axial_orientation); });
  p.source_label = atlas_pyramid(ex, p.layout, &Exemplar::segments, L, r, 0.0f,
                                 [&](const ImageView& s) { return label_pyramid(s, L, r); });
  if (!in.target_mask.empty()) p.target_mask = plain(in.target_mask);
  if (!in.target_orientation.empty()) p.target_angle = angle_pyramid(in.target_orientation, L, r, opt.axial_orientation);
  if (!in.target_segments.empty()) p.target_label = label_pyramid(in.target_segments, L, r);
  // Per plan layer: the merged layers, the plan's layer 0, have none.
  if (p.merged_layers) p.weight_maps.emplace_back();
  for (std::size_t i = std::size_t(p.merged_layers); i < in.target_weight_maps.size(); ++i)
    p.weight_maps.push_back(in.target_weight_maps[i].empty() ? std::vector<Image>{} : plain(in.target_weight_maps[i]));
  if (!in.reference.empty()) p.reference = build_pyramid(in.reference, L, r, opt.level_box_widths);
  if (!in.fixed.empty()) {
    p.fixed_mask = plain(in.fixed.mask);
    p.fixed_values = plain(in.fixed.values);
    if (!in.fixed.matches.empty()) {
      // The fixed matches at level 0 in atlas positions, then carried down.
      OffsetField f0(tw, th);
      for (std::size_t i = 0; i < f0.x.size(); ++i) {
        const float* m = in.fixed.matches.data + 3 * i;
        const int e = std::clamp(int(m[0]), 0, int(ex.size()) - 1);
        f0.set_position(i, m[1], m[2] + float(p.layout[0].rects[e].y0));
      }
      p.fixed_field.push_back(f0);
      for (int l = 1; l < L; ++l) {
        const FieldGeometry g{&p.layout[l], nullptr};
        p.fixed_field.push_back(resample_field(f0, p.layout[0], g, p.target[l].width(), p.target[l].height(),
                                               std::pow(r, l)));
      }
    }
  }
  std::vector<float> channel_weights = opt.style_channel_weights;
  if (!channel_weights.empty() && int(channel_weights.size()) != p.style_channels)
    throw ValueError(concat("style channel weights has ", channel_weights.size(), " values for ", p.style_channels,
                            " style channels"));
  channel_weights.resize(p.style_channels, 1.0f);
  for (float w : channel_weights) p.style_scales.push_back(std::sqrt(opt.style_weight * w));
  if (opt.window_sigma > 0) p.window = gaussian_window(opt.patch_size / 2, opt.window_sigma);
  terms_ = in.terms;
  if (auto usage = make_usage_term(opt)) terms_.insert(terms_.begin(), usage);
  if (in.inputs_read) in.inputs_read();
}

Solver::~Solver() = default;

int Solver::levels() const { return plan_->levels; }
int Solver::target_width(int l) const { return plan_->target_size.at(std::size_t(l)).first; }
int Solver::target_height(int l) const { return plan_->target_size.at(std::size_t(l)).second; }
const SourceLayout& Solver::layout(int l) const { return plan_->layout.at(std::size_t(l)); }
int Solver::guide_channels() const {
  int n = 0;
  for (int c : plan_->guide_channels) n += c;
  return n;
}
double Solver::kept_guide_variance() const { return plan_->kept_variance; }

int Solver::em_iterations(int l) const {
  const std::size_t k = std::size_t(coarsest() - l);
  return k < options_.em_schedule.size() ? options_.em_schedule[k] : options_.em_iterations;
}
int Solver::pm_iterations(int l) const {
  const std::size_t k = std::size_t(coarsest() - l);
  return k < options_.pm_schedule.size() ? options_.pm_schedule[k] : options_.pm_iterations;
}

namespace {

double mean_energy(const OffsetField& field, const SearchConstraints& cons) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < cons.target_active.size(); ++i)
    if (cons.target_active[i]) sum += field.dist[i], ++n;
  return n ? sum / double(n) : 0.0;
}

// Whether the last EM iteration lowered the energy, by less than `tolerance`
// of the one before: the iterations left would change little. One that
// raised it has not settled (the patch usage's reassignment can, and a later
// iteration then drops it again).
bool settles(const std::vector<double>& energy, double tolerance) {
  if (tolerance <= 0 || energy.size() < 2) return false;
  const double before = energy[energy.size() - 2], after = energy.back();
  return after <= before && before - after < tolerance * before;
}

}  // namespace

PatchSpace Solver::geometry(int l, FeatureImage& source, FeatureImage& target) const {
  const Plan& p = *plan_;
  std::tie(source.width, source.height) = p.source_size[std::size_t(l)];
  std::tie(target.width, target.height) = p.target_size[std::size_t(l)];
  PatchSpace space;
  space.source = &source;
  space.target = &target;
  space.radius = options_.patch_size / 2;
  space.axial = options_.axial_orientation;
  if (!p.source_angle.empty()) space.source_angle = p.source_angle[std::size_t(l)].data();
  if (!p.target_angle.empty()) space.target_angle = p.target_angle[std::size_t(l)].data();
  if (!p.window.empty()) space.window = p.window.data();
  return space;
}

void Solver::build_level(int l, Level& level, const LevelStart* start) const {
  const Image* fixed_mask = start ? start->fixed_mask : nullptr;
  Plan& p = *plan_;
  if (p.source[std::size_t(l)].empty())
    throw ValueError(concat("level ", l, " was solved with last_use; its pyramids are freed"));
  // The level's last use frees each float pyramid level as soon as its
  // features are built, so that the plan's copy and the features are not
  // both held through the solve (peak memory ~ pixels, not pixels x levels).
  const bool release = start && start->last_use;
  const int total = p.source[std::size_t(l)].channels();
  level.space = geometry(l, level.source, level.target);
  level.style = extract_channels(p.source[l].view(), 0, p.style_channels);
  Image lab = options_.color_space == ColorSpace::Lab ? srgb_to_lab(level.style.view()) : Image();
  // All channels as they are (the guides are weighted already), then the
  // style's as matched: no full-size copy of the guides.
  const std::vector<ChannelWrite> source_writes = {
      {0, p.source[l].view(), std::vector<float>(std::size_t(total), 1.0f)},
      {0, lab.empty() ? level.style.view() : lab.view(), p.style_scales}};
  std::vector<ChannelWrite> target_writes;
  if (total > p.style_channels) {
    const ImageView guides = p.target[l].view();
    target_writes.push_back({p.style_channels, guides, std::vector<float>(std::size_t(guides.channels), 1.0f)});
  }
  if (start) add_guide_target_writes(l, *start, target_writes);
  const bool weighted = std::any_of(p.weight_maps.begin(), p.weight_maps.end(), [](auto& m) { return !m.empty(); });
  allocate_features(level, source_writes, target_writes, weighted && !options_.fixed_point_weights);
  level.space.source = &level.source;
  level.space.target = &level.target;
  if (level.space.window) {
    level.window_channels = expand_window(level.space.window, level.space.radius, total);
    level.space.window_channels = level.window_channels.data();
  }
  level.source.set_channels(source_writes);  // source_writes dangle from here on
  lab = Image();
  if (release) p.source[l] = Image();
  // The target's features are allocated only now, once the plan's exemplar
  // level is freed: the two were not held at once (20 MB of the still's peak).
  const auto [target_w, target_h] = p.target_size[std::size_t(l)];
  level.target = level.source.like(target_w, target_h);
  level.target.set_channels(target_writes);
  if (release) p.target[l] = Image();
  const int sw = level.source.width, sh = level.source.height, tw = level.target.width, th = level.target.height;
  if (weighted) {
    level.target_weights = FeatureImage(tw, th, total);
    std::fill(level.target_weights.data.begin(), level.target_weights.data.end(), 1.0f);
    int first = p.style_channels;
    for (std::size_t g = 0; g < p.guide_channels.size(); first += p.guide_channels[g++]) {
      if (g >= p.weight_maps.size() || p.weight_maps[g].empty()) continue;
      const Image& map = p.weight_maps[g][l];
      for (std::size_t i = 0; i < map.pixel_count(); ++i)
        for (int c = 0; c < p.guide_channels[g]; ++c)
          level.target_weights.data[i * level.target_weights.stride + first + c] = std::max(0.0f, map.data()[i]);
    }
    level.space.target_weights = &level.target_weights;
    if (level.target.quantized()) mark_weighted_patches(level);
  }
  SearchConstraints& cons = level.constraints;
  const int margin = level.space.source_margin();
  const SourceLayout& lay = p.layout[std::size_t(l)];
  cons.layout = &lay;
  cons.source_valid.assign(std::size_t(sw) * sh, 0);
  for (const SourceRect& rect : lay.rects)  // centres keep the margin inside their own exemplar
    for (int y = rect.y0 + margin; y < rect.y0 + rect.height - margin; ++y)
      for (int x = margin; x < rect.width - margin; ++x) {
        const std::size_t i = std::size_t(y) * sw + x;
        cons.source_valid[i] = p.source_mask.empty() || p.source_mask[l].data()[i] > 0.5f;
      }
  cons.target_active.assign(std::size_t(tw) * th, 1);
  if (!p.target_mask.empty())
    for (std::size_t i = 0; i < cons.target_active.size(); ++i)
      cons.target_active[i] = p.target_mask[l].data()[i] > 0.5f || (l > 0 && p.target_mask[l].data()[i] > 0.0f);
  const Image* fixed = fixed_mask ? fixed_mask : (p.fixed_mask.empty() ? nullptr : &p.fixed_mask[std::size_t(l)]);
  if (fixed) {
    if (fixed->width() != tw || fixed->height() != th || fixed->channels() != 1)
      throw ValueError(concat("the fixed-pixel mask of level ", l, " must be ", tw, "x", th, " with 1 channel"));
    level.fixed.assign(cons.target_active.size(), 0);
    for (std::size_t i = 0; i < level.fixed.size(); ++i)
      if (fixed->data()[i] > 0.5f) level.fixed[i] = 1, cons.target_active[i] = 0;
    level.voters = cons.target_active;
    if (!fixed_mask && !p.fixed_field.empty()) {
      for (std::size_t i = 0; i < level.fixed.size(); ++i) level.voters[i] |= level.fixed[i];
      cons.target_matched = level.voters;
    }
  }
  if (!p.source_label.empty())
    for (std::size_t i = 0; i < std::size_t(sw) * sh; ++i)
      cons.source_segment.push_back(std::int32_t(std::lround(p.source_label[l].data()[i])));
  if (!p.target_label.empty())
    for (std::size_t i = 0; i < std::size_t(tw) * th; ++i)
      cons.target_segment.push_back(std::int32_t(std::lround(p.target_label[l].data()[i])));
  cons.finalize();
}

// The target pixels whose weights are not all 1, and the patches that cover
// one: the fixed-point distance corrects only those (patch_distance.hpp).
void Solver::mark_weighted_patches(Level& level) const {
  const FeatureImage& weights = level.target_weights;
  const int tw = weights.width, th = weights.height, r = level.space.radius;
  level.weighted_pixels.assign(std::size_t(tw) * th, 0);
  level.weighted_patches.assign(std::size_t(tw) * th, 0);
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x) {
      const float* w = weights.pixel(x, y);
      if (std::any_of(w, w + weights.stride, [](float v) { return v != 1.0f; }))
        level.weighted_pixels[std::size_t(y) * tw + x] = 1;
    }
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x) {
      if (!level.weighted_pixels[std::size_t(y) * tw + x]) continue;
      for (int py = std::max(0, y - r); py <= std::min(th - 1, y + r); ++py)
        std::fill_n(level.weighted_patches.begin() + std::ptrdiff_t(std::size_t(py) * tw + std::max(0, x - r)),
                    std::min(tw - 1, x + r) - std::max(0, x - r) + 1, std::uint8_t(1));
    }
  level.space.weighted_pixels = level.weighted_pixels.data();
  level.space.weighted_patches = level.weighted_patches.data();
}

// Fixed-point features where the patch distance has a fixed-point path:
// axis-aligned patches with no window; per-pixel weights are corrected for
// the patches that meet them (mark_weighted_patches), unless `in_float`. Their offsets
// and step are read off the writes (the target's too), so the level's
// features are never held in float as well (that copy was twice their size,
// and the peak at 1 Mpix). Allocates the exemplar's; the target's are made
// like them (FeatureImage::like).
void Solver::allocate_features(Level& level, const std::vector<ChannelWrite>& source_writes,
                               const std::vector<ChannelWrite>& target_writes, bool in_float) const {
  const int total = source_writes.front().image.channels;
  const int sw = level.source.width, sh = level.source.height;
  const PatchSpace& s = level.space;
  if (in_float || options_.feature_precision == FeaturePrecision::Float || s.rotated() || s.window) {
    level.source = FeatureImage(sw, sh, total);
    return;
  }
  const int max_value =
      options_.feature_precision == FeaturePrecision::Int8 ? FeatureImage::kFixed8 : FeatureImage::kFixed12;
  std::vector<float> offset;
  float step = 0.0f;
  fixed_point_range(source_writes, target_writes, total, plan_->style_channels, max_value, offset, step);
  level.source = FeatureImage::fixed_point(sw, sh, total, offset, step, max_value);
}

// Per-level guide targets (LevelStart::guide_targets) as writes over the
// target's guide slots, weighted like the plan's.
void Solver::add_guide_target_writes(int l, const LevelStart& start, std::vector<ChannelWrite>& writes) const {
  const Plan& p = *plan_;
  const auto [tw, th] = p.target_size[std::size_t(l)];
  for (const auto& [layer, image] : start.guide_targets) {
    if (layer < 0 || layer >= int(p.guide_weights.size()))
      throw ValueError(concat("guide layer ", layer, " does not exist (there are ", p.guide_weights.size(), ")"));
    if (layer < p.merged_layers)
      throw ValueError(concat("guide layer ", layer, " is merged by PCA: per-level guide targets need its channels "
                              "(guide_variance 1, or a weight map on it)"));
    const int plan_layer = p.plan_layer(layer), channels = p.guide_channels[std::size_t(plan_layer)];
    if (image->width() != tw || image->height() != th || image->channels() != channels)
      throw ValueError(concat("guide target of layer ", layer, " at level ", l, " must be ", tw, "x", th, " with ",
                              channels, " channels"));
    int first = p.style_channels;
    for (int k = 0; k < plan_layer; ++k) first += p.guide_channels[std::size_t(k)];
    writes.push_back({first, image->view(),
                      std::vector<float>(std::size_t(channels), std::sqrt(p.guide_weights[std::size_t(layer)]))});
  }
}

void Solver::set_target_style(Level& level, const Image& bprime) const {
  if (options_.color_space == ColorSpace::Lab)
    level.target.set_channels(0, srgb_to_lab(bprime.view()).view(), plan_->style_scales);
  else
    level.target.set_channels(0, bprime.view(), plan_->style_scales);
}

// Fixed pixels: their match (when given) and their value.
void Solver::fix_pixels(int l, const Level& level, const Image* given, OffsetField& field, Image& bprime) const {
  if (level.fixed.empty()) return;
  const Plan& p = *plan_;
  if (!given && p.fixed_values.empty()) throw ValueError("fixed pixels of a level need their values");
  const Image& values = given ? *given : p.fixed_values[std::size_t(l)];
  if (values.width() != field.width || values.height() != field.height || values.channels() != p.style_channels)
    throw ValueError(concat("fixed-pixel values of level ", l, " must be ", field.width, "x", field.height, " with ",
                            p.style_channels, " channels"));
  if (bprime.empty()) bprime = Image(field.width, field.height, p.style_channels);
  for (std::size_t i = 0; i < level.fixed.size(); ++i) {
    if (!level.fixed[i]) continue;
    std::copy_n(values.data() + i * p.style_channels, p.style_channels, bprime.data() + i * p.style_channels);
    if (given || p.fixed_field.empty()) continue;
    const OffsetField& f = p.fixed_field[std::size_t(l)];
    field.x[i] = f.x[i], field.y[i] = f.y[i], field.rx[i] = f.rx[i], field.ry[i] = f.ry[i];
  }
}

// A warm start's restarted pixels (LevelStart::restart_mask) are matched as
// a cold start's coarsest level is, on the guides alone, since their B' is
// unknown: from random matches, the first vote would show them the noise of
// random paint, which two EM iterations at full size do not undo (a pale
// ghost of what hid the surface; docs/benchmarks.md, issue 32). Only they
// search; their held neighbours propagate into them.
void Solver::restart_masked(int l, const Image& mask, const Level& level, OffsetField& field) const {
  if (mask.width() != field.width || mask.height() != field.height || mask.channels() != 1)
    throw ValueError(concat("a restart mask must be ", field.width, "x", field.height, " with 1 channel"));
  std::vector<std::uint8_t> restart(field.x.size());
  for (std::size_t i = 0; i < restart.size(); ++i) restart[i] = mask.data()[i] > 0.5f;
  restart_pixels(level.space, level.constraints, field, restart, options_.seed);
  if (plan_->guide_channels.empty() || std::find(restart.begin(), restart.end(), 1) == restart.end()) return;
  SearchConstraints restarted = level.constraints;
  restarted.target_matched = level.constraints.matched();
  for (std::size_t i = 0; i < restart.size(); ++i) restarted.target_active[i] &= restart[i];
  match_on_guides(level, restarted, field, pm_iterations(l));
}

// PatchMatch of `field` on the guide channels alone (B' zeroed on both sides).
void Solver::match_on_guides(const Level& level, const SearchConstraints& constraints, OffsetField& field,
                             int iterations) const {
  FeatureImage source = level.source, target = level.target;
  for (FeatureImage* f : {&source, &target}) f->zero_channels(0, plan_->style_channels);
  PatchSpace guide_space = level.space;
  guide_space.source = &source;
  guide_space.target = &target;
  refresh_distances(guide_space, constraints, field, options_.threads);
  PatchMatchParams pm{std::max(1, iterations), options_.seed, options_.threads};
  patchmatch(guide_space, constraints, field, pm, 0);
}

// Coarsest-level start without a field: match on the guides alone, since B'
// is unknown yet; with a reference, B' is the reference and the match uses it.
OffsetField Solver::cold_start(int l, Level& level, Image& bprime) const {
  const Plan& p = *plan_;
  OffsetField field;
  const std::uint64_t seed = options_.seed;
  if (!p.reference.empty()) {
    bprime = p.reference[std::size_t(l)];
    set_target_style(level, bprime);
    random_field(level.space, level.constraints, field, seed, options_.threads);
    PatchMatchParams pm{std::max(1, pm_iterations(l)), seed, options_.threads};
    patchmatch(level.space, level.constraints, field, pm, 0);
    return field;
  }
  random_field(level.space, level.constraints, field, seed, options_.threads);
  if (!p.guide_channels.empty()) match_on_guides(level, level.constraints, field, pm_iterations(l));
  return field;
}

void Solver::to_atlas(int l, int exemplar, float x, float y, float& ax, float& ay) const {
  const SourceLayout& lay = layout(l);
  if (exemplar < 0 || exemplar >= int(lay.rects.size()))
    throw ValueError(concat("exemplar ", exemplar, " does not exist (there are ", lay.rects.size(), ")"));
  ax = x;
  ay = y + float(lay.rects[std::size_t(exemplar)].y0);
}

ExemplarMatch Solver::match(int l, const OffsetField& field, std::size_t i) const {
  const SourceLayout& lay = layout(l);
  const int e = lay.source_at(field.y[i]);
  return {e, field.position_x(i), field.position_y(i) - float(lay.rects[std::size_t(e)].y0)};
}

ExemplarMatch SynthesisResult::match(int x, int y) const {
  const std::size_t i = field.index(x, y);
  const int e = layout.source_at(field.y[i]);
  return {e, field.position_x(i), field.position_y(i) - float(layout.rects[std::size_t(e)].y0)};
}

void require_level_size(const OffsetField& field, int w, int h, int l) {
  if (field.width != w || field.height != h)
    throw ValueError(concat("offset field is ", field.width, "x", field.height, " but level ", l, " is ", w, "x", h));
}

OffsetField Solver::resample(const OffsetField& field, int from, int to) const {
  require_level_size(field, target_width(from), target_height(from), from);
  FeatureImage source, target;
  const PatchSpace space = geometry(to, source, target);
  return resample_field(field, layout(from), FieldGeometry{&layout(to), &space}, target_width(to),
                        target_height(to), std::pow(plan_->ratio, to - from));
}

OffsetField Solver::advect(const OffsetField& field, int l, const ImageView& velocity_backward) const {
  require_level_size(field, target_width(l), target_height(l), l);
  FeatureImage source, target;
  const PatchSpace space = geometry(l, source, target);
  return advect_field(field, velocity_backward, FieldGeometry{&layout(l), &space});
}

double Solver::energy(int l, const OffsetField& field, const Image& image) const {
  Level level;
  build_level(l, level);
  set_target_style(level, image);
  OffsetField f = field;
  refresh_distances(level.space, level.constraints, f, options_.threads);
  return mean_energy(f, level.constraints);
}

LevelResult Solver::solve_level(int l, const LevelStart& start, const std::function<bool(double)>& progress) const {
  if (l < 0 || l >= levels()) throw ValueError(concat("level ", l, " does not exist (0 to ", coarsest(), ")"));
  const Plan& p = *plan_;
  Level level;
  build_level(l, level, &start);
  LevelResult out;
  LevelStats& stats = out.stats;
  stats.level = l;
  stats.width = level.target.width;
  stats.height = level.target.height;
  const int em = em_iterations(l), pm_iters = pm_iterations(l);
  const VoteParams vote_params{options_.output, options_.seed, 0, options_.threads,
                               level.voters.empty() ? nullptr : &level.voters};
  auto t0 = Clock::now();
  OffsetField& field = out.field;
  Image& bprime = out.image;
  const OffsetField* given = start.take_field ? start.take_field : start.field;
  if (given) {
    if (given->width != stats.width || given->height != stats.height)
      throw ValueError(concat("start field is ", given->width, "x", given->height, " but level ", l, " is ",
                              stats.width, "x", stats.height));
    if (start.take_field)
      field = std::move(*start.take_field);
    else
      field = *given;
    legalize_field(level.space, level.constraints, field);
    if (start.restart_mask) restart_masked(l, *start.restart_mask, level, field);
  } else {
    field = cold_start(l, level, bprime);
  }
  if (start.image && (start.image->width() != stats.width || start.image->height() != stats.height ||
                      start.image->channels() != p.style_channels))
    throw ValueError(concat("start image must be ", stats.width, "x", stats.height, " with ", p.style_channels,
                            " channels"));
  if (start.image_mask && (!start.image || start.image_mask->width() != stats.width ||
                           start.image_mask->height() != stats.height || start.image_mask->channels() != 1))
    throw ValueError(concat("a start image mask needs a start image and must be ", stats.width, "x", stats.height));
  if (start.image && !start.image_mask) bprime = *start.image;
  fix_pixels(l, level, start.fixed_values, field, bprime);
  stats.search_seconds += seconds_since(t0);
  const bool have_image = (start.image && !start.image_mask) || (!given && !p.reference.empty());
  if (!have_image) {  // vote it from the field
    t0 = Clock::now();
    bprime = vote(level.style.view(), level.space, level.constraints, field, bprime.view(), vote_params);
    stats.vote_seconds += seconds_since(t0);
  }
  if (start.image_mask)
    for (std::size_t i = 0; i < bprime.pixel_count(); ++i)
      if (start.image_mask->data()[i] > 0.5f)
        std::copy_n(start.image->data() + i * p.style_channels, p.style_channels, bprime.data() + i * p.style_channels);
  std::vector<std::int32_t> sources_before_search;
  const LevelContext context{l, &level.space, &level.constraints, &p.layout[std::size_t(l)], options_.seed,
                             options_.threads, &sources_before_search};
  PatchMatchParams pm{pm_iters, options_.seed, options_.threads};
  // The coarsest level searches the whole exemplar; finer ones refine the
  // matches it found, within search_radius after a first wide sweep.
  pm.search_radius = l == coarsest() ? 0 : options_.search_radius;
  pm.candidates = start.candidates;
  pm.context = &context;
  for (const auto& t : terms_)
    if (t->reads_field()) pm.field_terms.push_back(t.get());
  std::vector<TermState> states(terms_.size());
  const bool refresh_each_iteration =
      std::any_of(terms_.begin(), terms_.end(), [](const auto& t) { return t->refresh_each_iteration(); });
  // Converged pixels are skipped where a pixel's search problem depends on
  // its match, its neighbours' and its patch alone: not with terms that read
  // the field or price sources (they change with every other pixel), nor with
  // a method's candidates (new ones each level). Only at the finest level:
  // a match lost at a coarser level is upsampled and compounds (all levels:
  // +4.3% energy at 1 Mpix; the finest alone: within 2% of the full search,
  // docs/benchmarks.md, issue 11).
  const bool skip_converged = options_.skip_converged && pm.field_terms.empty() &&
                              (!pm.candidates || pm.candidates->empty()) && l == 0;
  std::vector<std::uint8_t> to_search;  // empty: search every active pixel
  std::vector<std::uint32_t> matches_before;
  std::vector<std::uint8_t> moved;  // by this iteration's search or budget
  for (int it = 0; it < em; ++it) {
    const std::uint64_t stream = std::uint64_t(l) * 1000 + std::uint64_t(it) + 1;
    t0 = Clock::now();
    set_target_style(level, bprime);
    refresh_distances(level.space, level.constraints, field, options_.threads);
    if (skip_converged) match_fingerprints(field, matches_before), moved.assign(matches_before.size(), 0);
    source_indices(field, level.space.source->width, sources_before_search);
    // One search, split into single iterations when a term's costs follow the field.
    const int chunk = refresh_each_iteration ? 1 : pm_iters;
    for (int first = 0; first < pm_iters; first += chunk) {
      level.constraints.source_cost.assign(level.constraints.source_valid.size(), 0.0f);
      for (std::size_t k = 0; k < terms_.size(); ++k)
        terms_[k]->add_source_costs(context, field, level.constraints.source_cost, states[k]);
      const bool source_costs = std::any_of(level.constraints.source_cost.begin(),
                                            level.constraints.source_cost.end(), [](float c) { return c != 0.0f; });
      if (!source_costs) level.constraints.source_cost.clear();
      PatchMatchParams part = pm;
      part.first_iteration = first, part.iterations = chunk;
      if (!to_search.empty() && !source_costs) {
        part.searched = &to_search;
        for (std::size_t i = 0; i < to_search.size(); ++i)
          stats.converged_skips += std::size_t(chunk) * (level.constraints.target_active[i] && !to_search[i]);
      }
      patchmatch(level.space, level.constraints, field, part, stream);
      level.constraints.source_cost.clear();
    }
    if (skip_converged) mark_moved(field, matches_before, moved);
    stats.search_seconds += seconds_since(t0);
    t0 = Clock::now();
    for (const auto& t : terms_) {
      const UsageStats us = t->reassign(context, field, stream);
      stats.usage_rounds += us.rounds;
      stats.usage_wide_searches += us.wide_searches;
      if (us.rounds > 0) stats.reversed_coverage = us.covered;
    }
    stats.usage_seconds += seconds_since(t0);
    stats.energy.push_back(mean_energy(field, level.constraints));
    // Only the finest level stops early: what a coarser level leaves
    // unsettled is upsampled and compounds, as with converged pixels.
    const bool settled = l == 0 && settles(stats.energy, options_.em_tolerance);
    t0 = Clock::now();
    VoteParams vp = vote_params;
    vp.stream = stream;
    Image voted = vote(level.style.view(), level.space, level.constraints, field, bprime.view(), vp);
    stats.vote_seconds += seconds_since(t0);
    if (skip_converged && !bprime.empty() && !settled) {
      t0 = Clock::now();
      mark_moved(field, matches_before, moved);
      to_search = pixels_to_search(field.width, field.height, moved, changed_pixels(bprime.view(), voted.view()),
                                   level.space.radius, level.constraints.target_active);
      stats.search_seconds += seconds_since(t0);
    }
    bprime = std::move(voted);
    if (progress && !progress(settled ? 1.0 : double(it + 1) / em)) throw CancelledError("synthesis cancelled");
    if (settled) break;
  }
  stats.source_coverage = source_coverage(field, level.constraints, level.source.width);
  return out;
}

}  // namespace tempera

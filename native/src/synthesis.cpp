#include "tempera/synthesis.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "tempera/error.hpp"
#include "tempera/limits.hpp"
#include "tempera/guide_compression.hpp"
#include "tempera/pyramid.hpp"
#include "tempera/voting.hpp"

namespace tempera {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void validate(const SynthesisInput& in, const SynthesisOptions& opt) {
  require_nonempty(in.style, "style");
  require_finite(in.style, "style");
  if (opt.patch_size < 3 || opt.patch_size % 2 == 0)
    throw ValueError(concat("patch size must be odd and >= 3, got ", opt.patch_size));
  if (opt.em_iterations < 1) throw ValueError(concat("em iterations must be >= 1, got ", opt.em_iterations));
  if (opt.pm_iterations < 0) throw ValueError(concat("pm iterations must be >= 0, got ", opt.pm_iterations));
  check_levels(opt.levels);  // tempera/limits.hpp
  if (opt.threads < 0) throw ValueError(concat("threads must be >= 0 (0 = all cores), got ", opt.threads));
  if (!std::isfinite(opt.style_weight) || opt.style_weight < 0)
    throw ValueError(concat("style weight must be finite and >= 0, got ", opt.style_weight));
  if (!std::isfinite(opt.penalty_weight) || opt.penalty_weight < 0)
    throw ValueError(concat("penalty weight must be finite and >= 0, got ", opt.penalty_weight));
  if (!(opt.guide_variance > 0 && opt.guide_variance <= 1))
    throw ValueError(concat("guide variance must be in (0, 1], got ", opt.guide_variance));
  if (!(opt.budget_coverage > 0 && opt.budget_coverage <= 1))
    throw ValueError(concat("budget coverage must be in (0, 1], got ", opt.budget_coverage));
  if (!in.guides.empty()) {
    require_same_size(in.guides.layers().front().source, "guide source", in.style, "style");
  } else if (in.target_width <= 0 || in.target_height <= 0) {
    throw ValueError("without guides the target size must be given");
  }
  const int tw = in.guides.empty() ? in.target_width : in.guides.target_width();
  const int th = in.guides.empty() ? in.target_height : in.guides.target_height();
  auto check_map = [&](const ImageView& map, const char* what, bool target) {
    if (map.empty()) return;
    if (map.channels != 1) throw ValueError(concat(what, " must have 1 channel, got ", map.channels));
    const int w = target ? tw : in.style.width, h = target ? th : in.style.height;
    if (map.width != w || map.height != h)
      throw ValueError(concat(what, " is ", map.width, "x", map.height, " but the ", target ? "target" : "style",
                              " is ", w, "x", h));
    require_finite(map, what);
  };
  check_map(in.source_mask, "source mask", false);
  check_map(in.target_mask, "target mask", true);
  check_map(in.source_orientation, "source orientation", false);
  check_map(in.target_orientation, "target orientation", true);
  check_map(in.source_segments, "source segments", false);
  check_map(in.target_segments, "target segments", true);
  for (const auto& map : in.target_weight_maps) check_map(map, "target weight map", true);
  if (in.target_weight_maps.size() > in.guides.layers().size())
    throw ValueError(concat(in.target_weight_maps.size(), " target weight maps for ", in.guides.layers().size(),
                            " guides"));
  auto any_inside = [](const ImageView& m) {
    for (std::size_t i = 0; i < m.size(); ++i)
      if (m.data[i] > 0.5f) return true;
    return false;
  };
  if (!in.source_mask.empty() && !any_inside(in.source_mask)) throw ValueError("source mask is empty");
  if (!in.target_mask.empty() && !any_inside(in.target_mask)) throw ValueError("target mask is empty");
  for (const auto* seg : {&in.source_segments, &in.target_segments})
    for (std::size_t i = 0; i < seg->size(); ++i)
      if (seg->data[i] < 0 || seg->data[i] > 65535)
        throw ValueError("segment labels must be integers in [0, 65535]");
  if (in.style.channels + in.guides.total_channels() > 248)
    throw ValueError(concat("too many channels (", in.style.channels + in.guides.total_channels(),
                            "); at most 248 style and guide channels are supported"));
}

// Concatenates images of equal size along channels.
Image stack_channels(const std::vector<ImageView>& parts) {
  int channels = 0;
  for (const auto& p : parts) channels += p.channels;
  Image out(parts.front().width, parts.front().height, channels);
  const std::size_t n = out.pixel_count();
  int first = 0;
  for (const auto& p : parts) {
    for (std::size_t i = 0; i < n; ++i)
      std::memcpy(out.data() + i * channels + first, p.data + i * p.channels, sizeof(float) * p.channels);
    first += p.channels;
  }
  return out;
}

// Angles downsample as unit vectors (averaging raw angles breaks at the
// wrap-around); axial angles as doubled-angle vectors, so a and a + pi agree.
std::vector<Image> angle_pyramid(const ImageView& angles, int levels, bool axial) {
  if (angles.empty()) return {};
  const float k = axial ? 2.0f : 1.0f;
  Image vec(angles.width, angles.height, 2);
  for (std::size_t i = 0; i < angles.pixel_count(); ++i) {
    vec.data()[2 * i] = std::cos(k * angles.data[i]);
    vec.data()[2 * i + 1] = std::sin(k * angles.data[i]);
  }
  std::vector<Image> out;
  for (auto& level : build_pyramid(vec.view(), levels)) {
    Image a(level.width(), level.height(), 1);
    for (std::size_t i = 0; i < a.pixel_count(); ++i)
      a.data()[i] = std::atan2(level.data()[2 * i + 1], level.data()[2 * i]) / k;
    out.push_back(std::move(a));
  }
  return out;
}

// Labels downsample by picking (no blending of unrelated labels).
std::vector<Image> label_pyramid(const ImageView& labels, int levels) {
  if (labels.empty()) return {};
  std::vector<Image> out;
  out.push_back(Image::copy_of(labels));
  for (int l = 1; l < levels; ++l) {
    const Image& prev = out.back();
    Image next(std::max(1, (prev.width() + 1) / 2), std::max(1, (prev.height() + 1) / 2), 1);
    for (int y = 0; y < next.height(); ++y)
      for (int x = 0; x < next.width(); ++x) next.at(x, y, 0) = prev.at(2 * x, 2 * y, 0);
    out.push_back(std::move(next));
  }
  return out;
}

Image scaled(const ImageView& image, float factor) {
  Image out = Image::copy_of(image);
  for (std::size_t i = 0; i < out.pixel_count() * out.channels(); ++i) out.data()[i] *= factor;
  return out;
}

std::vector<ImageView> views(const std::vector<Image>& images) {
  std::vector<ImageView> out;
  for (const auto& img : images) out.push_back(img.view());
  return out;
}

std::vector<Image> optional_pyramid(const ImageView& image, int levels) {
  return image.empty() ? std::vector<Image>{} : build_pyramid(image, levels);
}

// Everything the engine derives from the inputs once, for all levels.
struct Pyramids {
  int levels = 0;
  int style_channels = 0;
  std::vector<int> guide_channels;  // per guide layer (one merged layer after PCA)
  double kept_variance = 1.0;
  std::vector<Image> source, target;  // source: style + guides; target: guides
  std::vector<Image> source_mask, target_mask, source_angle, target_angle, source_label, target_label;
  std::vector<std::vector<Image>> weight_maps;  // per guide (may be empty)
};

Pyramids build_pyramids(const SynthesisInput& in, const SynthesisOptions& opt) {
  Pyramids p;
  const int tw = in.guides.empty() ? in.target_width : in.guides.target_width();
  const int th = in.guides.empty() ? in.target_height : in.guides.target_height();
  const int min_side = 4 * opt.patch_size;
  const int auto_levels = std::min(pyramid_levels_for(in.style.width, in.style.height, min_side),
                                   pyramid_levels_for(tw, th, min_side));
  p.levels = opt.levels > 0 ? opt.levels : auto_levels;
  p.style_channels = in.style.channels;
  // Guides are scaled by sqrt(weight) once here; after that every feature
  // channel but the style's has weight 1.
  std::vector<Image> weighted_src, weighted_tgt;
  for (const auto& layer : in.guides.layers()) {
    weighted_src.push_back(scaled(layer.source, std::sqrt(layer.weight)));
    weighted_tgt.push_back(scaled(layer.target, std::sqrt(layer.weight)));
    p.guide_channels.push_back(layer.source.channels);
  }
  Image src_guides, tgt_guides;
  if (!weighted_src.empty()) {
    src_guides = stack_channels(views(weighted_src));
    tgt_guides = stack_channels(views(weighted_tgt));
    weighted_src.clear();
    weighted_tgt.clear();
    const bool has_maps = std::any_of(in.target_weight_maps.begin(), in.target_weight_maps.end(),
                                      [](const ImageView& m) { return !m.empty(); });
    if (opt.guide_variance < 1.0 && !has_maps && src_guides.channels() > 1) {
      const GuideProjection proj = fit_guide_projection(src_guides.view(), tgt_guides.view(), opt.guide_variance);
      src_guides = proj.apply(src_guides.view());
      tgt_guides = proj.apply(tgt_guides.view());
      p.guide_channels = {proj.output_channels()};
      p.kept_variance = proj.kept_variance;
    }
  }
  p.source = build_pyramid(src_guides.empty() ? in.style : stack_channels({in.style, src_guides.view()}).view(),
                           p.levels);
  if (!tgt_guides.empty()) {
    p.target = build_pyramid(tgt_guides.view(), p.levels);
  } else {
    Image blank(tw, th, 1);
    for (int l = 0; l < p.levels; ++l) {
      p.target.push_back(blank);
      blank = downsample_half(blank.view());
    }
  }
  const auto& coarsest_source = p.source.back();
  if (coarsest_source.width() < opt.patch_size + 2 || coarsest_source.height() < opt.patch_size + 2) {
    if (p.levels == 1)
      throw ValueError(concat("the style is ", in.style.width, "x", in.style.height, " pixels; patch size ",
                              opt.patch_size, " needs at least ", opt.patch_size + 2, "x", opt.patch_size + 2));
    throw ValueError(concat("the style (", in.style.width, "x", in.style.height, ") is too small for ", p.levels,
                            " pyramid levels with patch size ", opt.patch_size,
                            "; use fewer levels (0 = automatic) or a larger exemplar"));
  }
  p.source_mask = optional_pyramid(in.source_mask, p.levels);
  p.target_mask = optional_pyramid(in.target_mask, p.levels);
  p.source_angle = angle_pyramid(in.source_orientation, p.levels, opt.axial_orientation);
  p.target_angle = angle_pyramid(in.target_orientation, p.levels, opt.axial_orientation);
  p.source_label = label_pyramid(in.source_segments, p.levels);
  p.target_label = label_pyramid(in.target_segments, p.levels);
  for (const auto& map : in.target_weight_maps) p.weight_maps.push_back(optional_pyramid(map, p.levels));
  return p;
}

// One pyramid level: features, constraints and the patch space over them.
struct Level {
  FeatureImage source, target, target_weights;
  SearchConstraints constraints;
  PatchSpace space;
  Image style;  // A' at this level (unweighted), what voting copies
};

// Features: style channels scaled by `style_scale`, guides as they are.
void fill_features(const Pyramids& p, int l, float style_scale, FeatureImage& source, FeatureImage& target) {
  const Image& src = p.source[l];
  const int total = src.channels();
  source = FeatureImage(src.width(), src.height(), total);
  target = FeatureImage(p.target[l].width(), p.target[l].height(), total);
  source.set_channels(0, src.view(), 1.0f);
  if (style_scale != 1.0f) {
    Image style = extract_channels(src.view(), 0, p.style_channels);
    source.set_channels(0, style.view(), style_scale);
  }
  if (!p.guide_channels.empty()) target.set_channels(p.style_channels, p.target[l].view(), 1.0f);
}

void build_level(const Pyramids& p, int l, const SynthesisOptions& opt, Level& level) {
  fill_features(p, l, std::sqrt(opt.style_weight), level.source, level.target);
  level.style = extract_channels(p.source[l].view(), 0, p.style_channels);
  const int sw = level.source.width, sh = level.source.height, tw = level.target.width, th = level.target.height;
  PatchSpace& space = level.space;
  space = PatchSpace{};
  space.source = &level.source;
  space.target = &level.target;
  space.radius = opt.patch_size / 2;
  space.axial = opt.axial_orientation;
  if (!p.source_angle.empty()) space.source_angle = p.source_angle[l].data();
  if (!p.target_angle.empty()) space.target_angle = p.target_angle[l].data();
  const bool weighted = std::any_of(p.weight_maps.begin(), p.weight_maps.end(), [](auto& m) { return !m.empty(); });
  if (weighted) {
    level.target_weights = FeatureImage(tw, th, p.source[l].channels());
    std::fill(level.target_weights.data.begin(), level.target_weights.data.end(), 1.0f);
    int first = p.style_channels;
    for (std::size_t g = 0; g < p.guide_channels.size(); first += p.guide_channels[g++]) {
      if (g >= p.weight_maps.size() || p.weight_maps[g].empty()) continue;
      const Image& map = p.weight_maps[g][l];
      for (std::size_t i = 0; i < map.pixel_count(); ++i)
        for (int c = 0; c < p.guide_channels[g]; ++c)
          level.target_weights.data[i * level.target_weights.stride + first + c] = std::max(0.0f, map.data()[i]);
    }
    space.target_weights = &level.target_weights;
  }
  SearchConstraints& cons = level.constraints;
  const int margin = space.source_margin();
  cons.source_valid.assign(std::size_t(sw) * sh, 0);
  for (int y = margin; y < sh - margin; ++y)
    for (int x = margin; x < sw - margin; ++x) {
      const std::size_t i = std::size_t(y) * sw + x;
      cons.source_valid[i] = p.source_mask.empty() || p.source_mask[l].data()[i] > 0.5f;
    }
  cons.target_active.assign(std::size_t(tw) * th, 1);
  if (!p.target_mask.empty())
    for (std::size_t i = 0; i < cons.target_active.size(); ++i)
      cons.target_active[i] = p.target_mask[l].data()[i] > 0.5f || (l > 0 && p.target_mask[l].data()[i] > 0.0f);
  if (!p.source_label.empty())
    for (float v : std::vector<float>(p.source_label[l].data(), p.source_label[l].data() + sw * sh))
      cons.source_segment.push_back(std::int32_t(std::lround(v)));
  if (!p.target_label.empty())
    for (float v : std::vector<float>(p.target_label[l].data(), p.target_label[l].data() + tw * th))
      cons.target_segment.push_back(std::int32_t(std::lround(v)));
  cons.finalize();
}

// Writes B' into the style slots of the target features.
void set_target_style(Level& level, const Image& bprime, float style_scale) {
  level.target.set_channels(0, bprime.view(), style_scale);
}

double mean_energy(const Nnf& nnf, const SearchConstraints& cons) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < cons.target_active.size(); ++i)
    if (cons.target_active[i]) sum += nnf.dist[i], ++n;
  return n ? sum / double(n) : 0.0;
}

// Coarsest level: match on the guides alone first, since B' is unknown yet.
Nnf initial_nnf(const Pyramids& p, int l, Level& level, const SynthesisOptions& opt) {
  Nnf nnf;
  if (p.guide_channels.empty()) {
    random_nnf(level.space, level.constraints, nnf, opt.seed, opt.threads);
    return nnf;
  }
  FeatureImage source, target;
  fill_features(p, l, 0.0f, source, target);
  PatchSpace guide_space = level.space;
  guide_space.source = &source;
  guide_space.target = &target;
  random_nnf(guide_space, level.constraints, nnf, opt.seed, opt.threads);
  PatchMatchParams pm{std::max(1, opt.pm_iterations), opt.seed, opt.threads};
  patchmatch(guide_space, level.constraints, nnf, pm, 0);
  return nnf;
}

}  // namespace

SynthesisResult synthesize(const SynthesisInput& in, const SynthesisOptions& opt, const ProgressCallback& progress) {
  validate(in, opt);
  const auto t_start = Clock::now();
  const Pyramids pyr = build_pyramids(in, opt);
  const float style_scale = std::sqrt(opt.style_weight);
  double total_work = 0, done_work = 0;
  for (int l = 0; l < pyr.levels; ++l) total_work += double(pyr.target[l].pixel_count()) * opt.em_iterations;
  auto report = [&](double work) {
    done_work += work;
    if (progress && !progress(std::min(1.0, done_work / total_work)))
      throw CancelledError("synthesis cancelled");
  };

  SynthesisResult result;
  Nnf nnf;
  Image bprime;
  for (int l = pyr.levels - 1; l >= 0; --l) {
    Level level;
    build_level(pyr, l, opt, level);
    LevelStats stats;
    stats.level = l;
    stats.width = level.target.width;
    stats.height = level.target.height;
    auto t0 = Clock::now();
    nnf = (l == pyr.levels - 1)
              ? initial_nnf(pyr, l, level, opt)
              : upsample_nnf(nnf, level.space, level.constraints, level.target.width, level.target.height);
    stats.search_seconds += seconds_since(t0);
    t0 = Clock::now();
    bprime = vote(level.style.view(), level.space, level.constraints, nnf, {}, opt.threads);
    stats.vote_seconds += seconds_since(t0);
    for (int it = 0; it < opt.em_iterations; ++it) {
      const std::uint64_t stream = std::uint64_t(l) * 1000 + std::uint64_t(it) + 1;
      t0 = Clock::now();
      set_target_style(level, bprime, style_scale);
      refresh_distances(level.space, level.constraints, nnf, opt.threads);
      if (opt.usage == PatchUsage::Penalty)
        level.constraints.source_penalty =
            occurrence_penalty(nnf, level.constraints, level.source.width, opt.penalty_weight);
      patchmatch(level.space, level.constraints, nnf, PatchMatchParams{opt.pm_iterations, opt.seed, opt.threads},
                 stream);
      level.constraints.source_penalty.clear();
      stats.search_seconds += seconds_since(t0);
      t0 = Clock::now();
      ReversedRetrievalParams rr;
      rr.coverage_goal = opt.budget_coverage;
      rr.max_rounds = opt.budget_max_rounds;
      rr.seed = opt.seed;
      rr.threads = opt.threads;
      ReversedRetrievalStats rs;
      if (opt.usage == PatchUsage::Uniform) rs = retrieve_uniform(level.space, level.constraints, nnf, rr, stream);
      if (opt.usage == PatchUsage::Budget) rs = retrieve_with_budget(level.space, level.constraints, nnf, rr, stream);
      stats.usage_rounds += rs.rounds;
      stats.reversed_coverage = rs.covered;
      stats.usage_seconds += seconds_since(t0);
      stats.energy.push_back(mean_energy(nnf, level.constraints));
      t0 = Clock::now();
      bprime = vote(level.style.view(), level.space, level.constraints, nnf, bprime.view(), opt.threads);
      stats.vote_seconds += seconds_since(t0);
      report(double(stats.width) * stats.height);
    }
    result.levels.push_back(std::move(stats));
    if (l == 0) result.source_coverage = source_coverage(nnf, level.constraints, level.source.width);
  }
  result.image = std::move(bprime);
  result.nnf = std::move(nnf);
  result.seconds = seconds_since(t_start);
  result.guide_channels = 0;
  for (int c : pyr.guide_channels) result.guide_channels += c;
  result.kept_guide_variance = pyr.kept_variance;
  return result;
}

}  // namespace tempera

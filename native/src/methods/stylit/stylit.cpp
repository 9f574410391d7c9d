#include "tempera/methods/stylit/stylit.hpp"

#include <algorithm>
#include <cmath>

#include "tempera/engine/error.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/engine/motion.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/engine/parallel.hpp"

namespace tempera {
namespace {

void require_channels(const ImageView& image, int channels, const char* what) {
  if (image.channels != channels)
    throw ValueError(concat(what, " must have ", channels, " channel(s), got ", image.channels));
}

// EM iterations of a warm-started frame. Measured on the demo shot (320x240,
// frames 2-8, temporal 0.5; bench/bench_warm_start.py, docs/benchmarks.md):
// against cold frames, 1 iteration ends 3% above their energy, 2 within 0.5%
// at 3.6x their speed, 3 2.9% below at 2.6x.
constexpr int kWarmEmIterations = 2;

}  // namespace

std::vector<std::pair<std::string, float>> active_guides(const StylitOptions& options) {
  auto out = active_guides(options.weights);
  if (!std::isfinite(options.temporal_weight) || options.temporal_weight < 0)
    throw ValueError(concat("temporal weight must be finite and >= 0, got ", options.temporal_weight));
  return out;
}

bool warm_starts(const StylitOptions& options) {
  return options.warm_start == WarmStart::On || (options.warm_start == WarmStart::Auto && options.temporal_weight > 0);
}

SynthesisOptions engine_options(const StylitOptions& options) {
  SynthesisOptions opt = options.synthesis;
  // The temporal guide's occlusion weights keep the fixed-point features:
  // 1.5x faster frames, energy within 1% (docs/benchmarks.md, issue 32).
  opt.fixed_point_weights = true;
  if (options.quality == Quality::Preview) {
    // Measured at 320x240 (docs/engine.md): about 5x faster than final; the
    // coarse levels settle with few iterations and the finest level gets the
    // error-budget rounds that matter most for the look.
    opt.em_iterations = 2;
    opt.pm_iterations = 1;
    opt.budget_max_rounds = 4;
  }
  return opt;
}

SynthesisResult stylize_frame(const ImageView& style, const GuideFrame& exemplar, const GuideFrame& target,
                              const TemporalInput* temporal, const StylitOptions& options,
                              const ProgressCallback& progress) {
  require_nonempty(style, "style");
  const auto guides = active_guides(options);
  // Tone-mapped copies must outlive the engine call: the stack holds views.
  std::vector<Image> tonemapped;
  tonemapped.reserve(2 * guides.size() + 1);
  SynthesisInput in;
  in.style = style;
  for (const auto& [name, weight] : guides) {
    const Image& src = exemplar.get(name);
    const Image& tgt = target.get(name);
    if (src.width() != style.width || src.height() != style.height)
      throw ValueError(concat("exemplar guide '", name, "' of '", exemplar.origin, "' is ", src.width(), "x",
                              src.height(), " but the style is ", style.width, "x", style.height));
    tonemapped.push_back(tonemap_guide(src.view()));
    tonemapped.push_back(tonemap_guide(tgt.view()));
    in.guides.add(name, tonemapped[tonemapped.size() - 2].view(), tonemapped.back().view(), weight);
  }
  if (temporal && options.temporal_weight > 0) {
    const ImageView tgt = in.guides.layers().front().target;
    require_channels(temporal->previous, style.channels, "previous stylized frame");
    require_same_size(temporal->previous, "previous stylized frame", tgt, "the target guides");
    require_channels(temporal->occlusion_backward, 1, "occlusion_backward");
    require_same_size(temporal->occlusion_backward, "occlusion_backward", tgt, "the target guides");
    tonemapped.push_back(warp_backward(temporal->previous, temporal->velocity_backward));
    // Source side is the painting itself: a target pixel is pulled towards the
    // paint it showed in the previous frame, carried along with the surface.
    in.guides.add("temporal", style, tonemapped.back().view(), options.temporal_weight);
    in.target_weight_maps.assign(guides.size(), ImageView{});
    in.target_weight_maps.push_back(temporal->occlusion_backward);  // disoccluded: no pull
  }
  // The copies are read once, into the solver's own guides: freed there, they
  // do not add to the frame's peak (two per guide, at the frame's size).
  in.guides_read = [&] { tonemapped = {}; };
  SynthesisOptions engine = engine_options(options);
  if (!warm_starts(options) || !temporal || !temporal->previous_field) return synthesize(in, engine, progress);
  require_channels(temporal->velocity_backward, 2, "velocity_backward");
  require_channels(temporal->occlusion_backward, 1, "occlusion_backward");
  engine.em_schedule.clear();
  engine.em_iterations = std::min(engine.em_iterations, kWarmEmIterations);
  return synthesize_warm(in, engine, *temporal->previous_field, temporal->velocity_backward,
                         temporal->occlusion_backward, progress);
}

double flicker(const ImageView& previous, const ImageView& current, const ImageView& velocity_backward,
               const ImageView& visible) {
  require_same_size(previous, "previous frame", current, "current frame");
  if (previous.channels != current.channels)
    throw ValueError(concat("previous frame has ", previous.channels, " channels, current frame ",
                            current.channels));
  require_channels(visible, 1, "visibility");
  require_same_size(visible, "visibility", current, "current frame");
  const Image advected = warp_backward(previous, velocity_backward);
  double sum = 0;
  std::size_t count = 0;
  for (int y = 0; y < current.height; ++y)
    for (int x = 0; x < current.width; ++x) {
      if (visible.at(x, y, 0) == 0.0f) continue;
      for (int c = 0; c < current.channels; ++c) sum += std::abs(double(current.at(x, y, c)) - advected.at(x, y, c));
      count += std::size_t(current.channels);
    }
  return count ? sum / double(count) : 0.0;
}

}  // namespace tempera

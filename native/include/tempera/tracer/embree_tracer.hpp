#pragma once
// Light-path-expression guides by path tracing (Embree 3 for ray queries).
// One pass fills one radiance image per expression: every path's event string
// is matched against every expression, and its contributions go to the
// images of the expressions it matches (the sets need not be disjoint).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/tracer/scene.hpp"

namespace tempera {

// Samples per pixel at most: a path's random stream is pixel * 2^20 + sample.
inline constexpr int kMaxTraceSamples = 1 << 20;

struct TraceOptions {
  int samples = 64;   // per pixel, stratified
  std::uint64_t seed = 0;
  int threads = 0;    // 0: all cores; the result does not depend on it
  // Indirect bounces as Cycles counts them: 0 gives direct light only (one
  // scattering event per path), 8 allows paths of up to nine.
  int max_bounces = 8;
  // Cycles' per-kind limits (Light Paths > Max Bounces), counted the same
  // way; a path ends once any count exceeds its limit. Transparent surfaces
  // are passed without a bounce, up to transparent_bounces of them.
  int diffuse_bounces = 1024, glossy_bounces = 1024, transmission_bounces = 1024, transparent_bounces = 1024;
  // Cycles' caustics options: false drops glossy (reflective) or refractive
  // lobes at a vertex reached by a diffuse bounce, so those paths do not exist.
  bool caustics_reflective = true, caustics_refractive = true;
  // Cycles' Filter Glossy (Blender's blur_glossy; 0: off): after a bounce of
  // pdf p (the smallest so far), glossy lobes get a microfacet alpha of at
  // least sqrt(1 - p * (1 / filter_glossy)) / 2 where that is below 1.
  float filter_glossy = 0;
  // Cycles' pixel filter (Film > Pixel Filter): camera rays are spread over
  // the filter's footprint, importance-sampled per axis as Cycles does: a box
  // of filter_width pixels, a Gaussian over 3 and a Blackman-Harris window
  // over 2 filter widths (Cycles' footprints). The default, a box of width 1,
  // is the pixel itself.
  enum class PixelFilter { box, gaussian, blackman_harris } pixel_filter = PixelFilter::box;
  float filter_width = 1;
};

template <>
struct EnumNames<TraceOptions::PixelFilter> {
  static constexpr const char* what = "pixel filter";
  static constexpr std::array<const char*, 3> names = {"box", "gaussian", "blackman_harris"};
};

// The one table of the tracer's options: their ranges (checked by
// trace_lpe), Python's tempera.TraceOptions and trace_lpe keywords with their
// defaults and help. Not on the command line: render-guides takes them from
// the scene's Cycles settings.
inline const auto& trace_option_table() {
  using T = TraceOptions;
  static const auto table = std::make_tuple(
      field(&T::samples, "samples", "", "camera rays per pixel, stratified", 1, kMaxTraceSamples),
      field(&T::seed, "seed", "", "random seed: the result depends on it, never on threads"),
      not_in_settings(field(&T::threads, "threads", "", "worker threads; 0 = all cores", 0)),
      field(&T::max_bounces, "max_bounces", "", "indirect bounces as Cycles counts them; 0 = direct light only", 0),
      field(&T::diffuse_bounces, "diffuse_bounces", "", "Cycles' Max Bounces > Diffuse", 0),
      field(&T::glossy_bounces, "glossy_bounces", "", "Cycles' Max Bounces > Glossy", 0),
      field(&T::transmission_bounces, "transmission_bounces", "", "Cycles' Max Bounces > Transmission", 0),
      field(&T::transparent_bounces, "transparent_bounces", "",
            "Cycles' Max Bounces > Transparent: transparent surfaces passed without a bounce", 0),
      field(&T::caustics_reflective, "caustics_reflective", "",
            "Cycles' Reflective Caustics: off drops glossy lobes after a diffuse bounce"),
      field(&T::caustics_refractive, "caustics_refractive", "",
            "Cycles' Refractive Caustics: off drops refractive lobes after a diffuse bounce"),
      field(&T::filter_glossy, "filter_glossy", "", "Cycles' Filter Glossy; 0 = off", 0),
      field(&T::pixel_filter, "pixel_filter", "", "Cycles' Film > Pixel Filter"),
      field(&T::filter_width, "filter_width", "", "Cycles' Film > Pixel Filter width in pixels, above 0", 0, 64));
  return table;
}

struct TraceResult {
  std::vector<Image> images;  // (H, W, 3) linear radiance, one per expression
  Image alpha;                // (H, W, 1) fraction of camera rays that hit geometry
};

// Called with the fraction done; returning false cancels (CancelledError).
using TraceProgress = std::function<bool(double)>;

// Throws ValueError for a malformed expression or scene, or options outside
// their table's ranges, and a tempera error carrying Embree's message if
// Embree fails.
TraceResult trace_lpe(const Scene& scene, const std::vector<std::string>& expressions,
                      const TraceOptions& options, const TraceProgress& progress = {});

}  // namespace tempera

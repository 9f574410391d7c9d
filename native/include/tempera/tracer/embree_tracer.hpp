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
#include "tempera/tracer/scene.hpp"

namespace tempera {

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

struct TraceResult {
  std::vector<Image> images;  // (H, W, 3) linear radiance, one per expression
  Image alpha;                // (H, W, 1) fraction of camera rays that hit geometry
};

// Called with the fraction done; returning false cancels (CancelledError).
using TraceProgress = std::function<bool(double)>;

// Throws ValueError for a malformed expression or scene, and a tempera error
// carrying Embree's message if Embree fails.
TraceResult trace_lpe(const Scene& scene, const std::vector<std::string>& expressions,
                      const TraceOptions& options, const TraceProgress& progress = {});

}  // namespace tempera

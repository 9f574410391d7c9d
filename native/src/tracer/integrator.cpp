// Unidirectional path tracer for light-path-expression guides.
//
// Paths start at the camera. Each scattering vertex samples one lobe of the
// material's BSDF (bsdf.hpp) and is labelled with that lobe's event (D, S or
// T); transparent surfaces are passed without an event. Light reached at a
// vertex, by next-event estimation (NEE) or by a BSDF-sampled ray, adds the
// event L. Every expression keeps one DFA state (compiled eye-to-light) per
// path, so matching costs one table lookup per vertex, and a path stops as
// soon as no expression can match any extension.
//
// NEE evaluates the lobes of each event separately (one contribution per
// label) so that LDE and LSE stay apart; BSDF-sampled hits on area lights,
// emissive triangles and a mapped world are weighted against NEE by the power
// heuristic with the BSDF's mixture pdf. Point, spot and sun lights are
// reached by NEE only; a constant world only by BSDF-sampled rays. A light's
// own Max Bounces and Multiple Importance switches act as in Cycles (scene.hpp).
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include "bsdf.hpp"
#include "embree_scene.hpp"
#include "lights.hpp"
#include "sampling.hpp"
#include "tempera/tracer/embree_tracer.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/tracer/lpe.hpp"
#include "tempera/engine/parallel.hpp"
#include "tempera/engine/rng.hpp"

namespace tempera {
namespace {

using namespace tracer;

constexpr int kRouletteFromBounce = 3;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

unsigned ray_kind(LpeEvent event) {
  return event == LpeEvent::D ? kVisibleDiffuse : event == LpeEvent::S ? kVisibleGlossy : kVisibleTransmission;
}

// The pixel filter's inverse CDF along one axis: u in [0, 1) -> an offset
// from the pixel centre, in pixels. The filter is separable, as in Cycles.
class FilterTable {
 public:
  // Cycles spreads its Gaussian over 3 and its Blackman-Harris over 2 filter
  // widths (measured: a Blackman-Harris of width 1.5 matches Cycles' default
  // per pixel when spread over 3 pixels, 0.9 % RMS against 4.2 % for the box).
  explicit FilterTable(const TraceOptions& o)
      : width_(o.filter_width * (o.pixel_filter == TraceOptions::PixelFilter::gaussian          ? 3.0f
                                 : o.pixel_filter == TraceOptions::PixelFilter::blackman_harris ? 2.0f
                                                                                                  : 1.0f)),
        box_(o.pixel_filter == TraceOptions::PixelFilter::box) {
    if (box_) return;
    constexpr int kSteps = 1024;
    std::vector<double> cdf(kSteps + 1, 0.0);
    for (int i = 0; i < kSteps; ++i) {
      const double x = (double(i) + 0.5) / kSteps - 0.5;  // in filter widths, [-0.5, 0.5)
      double w;
      if (o.pixel_filter == TraceOptions::PixelFilter::gaussian) {
        const double v = x * 6.0;  // Cycles: the Gaussian spans +-3 of its widths
        w = std::exp(-2.0 * v * v);
      } else {  // 4-term Blackman-Harris window over the width
        const double a = 2 * kPi * (x + 0.5);
        w = 0.35875 - 0.48829 * std::cos(a) + 0.14128 * std::cos(2 * a) - 0.01168 * std::cos(3 * a);
      }
      cdf[std::size_t(i) + 1] = cdf[std::size_t(i)] + std::max(w, 0.0);
    }
    table_.resize(kTable);
    std::size_t j = 0;
    for (int k = 0; k < kTable; ++k) {
      const double target = (double(k) + 0.5) / kTable * cdf[kSteps];
      while (j + 1 < cdf.size() - 1 && cdf[j + 1] < target) ++j;
      const double span = cdf[j + 1] - cdf[j];
      const double t = span > 0 ? (target - cdf[j]) / span : 0.5;
      table_[std::size_t(k)] = float(((double(j) + t) / kSteps - 0.5) * width_);
    }
  }
  float offset(float u) const {
    if (box_) return (u - 0.5f) * width_;
    const float f = u * float(kTable - 1);
    const int i = std::min(int(f), kTable - 2);
    return table_[std::size_t(i)] + (table_[std::size_t(i) + 1] - table_[std::size_t(i)]) * (f - float(i));
  }

 private:
  static constexpr int kTable = 512;
  float width_;
  bool box_;
  std::vector<float> table_;
};

class Tracer {
 public:
  Tracer(const Scene& scene, const std::vector<LpeDfa>& dfas, const TraceOptions& options)
      : scene_(scene), dfas_(dfas), options_(options), bvh_(scene, options.threads), world_(scene),
        filter_(options) {
    // Emissive triangles are sampled by area times luminance of (constant) emission.
    triangle_light_pdf_.assign(scene.triangles.size(), 0.0f);
    std::vector<double> power;
    for (std::uint32_t t = 0; t < scene.triangles.size(); ++t) {
      const float p = luminance(constant_emission(material(t))) * triangle_area(t);
      if (!(p > 0)) continue;
      emissive_.push_back(t);
      power.push_back(p);
    }
    emissive_pick_ = Distribution1D(power);
    for (std::size_t i = 0; i < emissive_.size(); ++i)
      triangle_light_pdf_[emissive_[i]] = emissive_pick_.probability(i) / triangle_area(emissive_[i]);
    for (const Material& m : scene.materials) any_transparent_ |= has_transparency(m);
  }

  // Radiance of one pixel sample, accumulated into sums[expression].
  void trace_sample(int px, int py, std::uint32_t index, std::uint32_t scramble_x, std::uint32_t scramble_y,
                    Rng& rng, std::vector<int>& states, std::vector<Float3>& sums, float& alpha) const {
    const Camera& cam = scene_.camera;
    const float sx = 0.5f + filter_.offset(scrambled(sobol_dim0(index), scramble_x));
    const float sy = 0.5f + filter_.offset(scrambled(sobol_dim1(index), scramble_y));
    const float ndc_x = 2 * (float(px) + sx) / float(cam.width) - 1;
    const float ndc_y = 1 - 2 * (float(py) + sy) / float(cam.height);
    Float3 origin, direction;
    float depth_scale;  // ray length per unit of view depth
    if (cam.type == Camera::Type::perspective) {
      const float t = cam.width >= cam.height ? cam.tan_half_fov_x : cam.tan_half_fov_y;
      const Float3 d{ndc_x * cam.tan_half_fov_x + 2 * cam.shift_x * t, ndc_y * cam.tan_half_fov_y + 2 * cam.shift_y * t,
                     -1};
      depth_scale = length(d);
      origin = transform_point({0, 0, 0});
      direction = normalize(transform_vector(d));
    } else {
      const float s = std::max(cam.ortho_width, cam.ortho_height);
      origin = transform_point({ndc_x * cam.ortho_width / 2 + cam.shift_x * s,
                                ndc_y * cam.ortho_height / 2 + cam.shift_y * s, 0});
      direction = normalize(transform_vector({0, 0, -1}));
      depth_scale = 1;
    }
    float t_near = cam.clip_start * depth_scale, t_far = cam.clip_end * depth_scale;

    bool any_alive = false;
    for (std::size_t k = 0; k < dfas_.size(); ++k) {
      states[k] = dfas_[k].step(dfas_[k].start, LpeEvent::E);
      any_alive |= dfas_[k].alive(states[k]);
    }
    Float3 throughput{1, 1, 1};
    float previous_pdf = 0;   // mixture pdf of the BSDF sample that led here; 0: camera or singular
    float travelled = 0;      // distance along this direction since the last scattering vertex
    float min_ray_pdf = kInfinity;  // smallest pdf of the non-singular bounces so far (Filter Glossy)
    unsigned kind = kVisibleCamera;
    int bounces = 0, diffuse = 0, glossy = 0, transmission = 0, transparent = 0;
    bool after_diffuse = false, first = true;
    for (;;) {
      EmbreeScene::Hit hit{};
      const bool hit_geometry = bvh_.intersect(origin, direction, t_near, t_far, hit, kind);
      if (first && hit_geometry) alpha += 1;
      first = false;
      if (!any_alive) return;
      const float t_geometry = hit_geometry ? hit.t : t_far;
      add_area_lights_crossed(origin, direction, t_near, t_geometry, travelled, kind, throughput, previous_pdf,
                              states, sums);
      if (!hit_geometry) {
        if (scene_.world_visibility & kind) {
          const float weight = world_.sampled() ? mis_weight(previous_pdf, world_.pdf(direction)) : 1.0f;
          add_emission(states, sums, throughput * world_.radiance(direction), weight);
        }
        return;
      }
      const SurfaceInput at = surface_input(hit, origin, direction);
      ShadingPoint s = shade(scene_, material(hit.triangle), at);
      if (max_component(s.emission) > 0) {
        const float distance = travelled + hit.t;
        const float cos_l = std::fabs(dot(s.ng, direction));
        const float pdf_light = triangle_light_pdf_[hit.triangle] * distance * distance / cos_l;
        add_emission(states, sums, throughput * s.emission, mis_weight(previous_pdf, pdf_light));
      }
      if (bounces > options_.max_bounces || diffuse > options_.diffuse_bounces || glossy > options_.glossy_bounces ||
          transmission > options_.transmission_bounces)
        return;
      if (after_diffuse) filter_caustics(s, options_.caustics_reflective, options_.caustics_refractive);
      if (options_.filter_glossy > 0 && std::isfinite(min_ray_pdf)) {
        const float blur_pdf = min_ray_pdf / options_.filter_glossy;
        if (blur_pdf < 1) blur_glossy(s, std::sqrt(1 - blur_pdf) * 0.5f);
      }
      next_event(s, throughput, bounces, states, sums, rng);

      Scatter scatter;
      if (!sample(s, rng, scatter)) return;
      if (!scatter.lobe) {  // transparent: straight on, no event, no bounce
        if (++transparent > options_.transparent_bounces) return;
        throughput *= scatter.weight;
        travelled += hit.t;
        origin = offset(at.p, at.ng, direction);
        t_near = 0;
        t_far = std::isinf(t_far) ? t_far : std::max(0.0f, t_far - hit.t);
        continue;
      }
      any_alive = false;
      for (std::size_t k = 0; k < dfas_.size(); ++k) {
        states[k] = dfas_[k].step(states[k], scatter.event);
        any_alive |= dfas_[k].alive(states[k]);
      }
      if (!any_alive) return;
      throughput *= scatter.weight;
      if (bounces >= kRouletteFromBounce) {
        const float survive = std::min(0.95f, max_component(throughput));
        if (!(rng.uniform() < survive)) return;
        throughput = throughput / survive;
      }
      ++bounces;
      if (scatter.lobe->diffuse()) ++diffuse;
      else if (scatter.event == LpeEvent::S) ++glossy;
      else ++transmission;
      after_diffuse = scatter.lobe->diffuse();
      kind = scatter.lobe->diffuse() ? kVisibleDiffuse : ray_kind(scatter.event);
      previous_pdf = scatter.pdf;
      if (scatter.pdf > 0) min_ray_pdf = std::min(min_ray_pdf, scatter.pdf);
      travelled = 0;
      origin = offset(at.p, at.ng, scatter.wi);
      direction = scatter.wi;
      t_near = 0;
      t_far = kInfinity;
    }
  }

 private:
  const Material& material(std::uint32_t t) const { return scene_.materials[scene_.triangle_materials[t]]; }
  Float3 corner(std::uint32_t t, int c) const { return scene_.vertices[scene_.triangles[t][c]]; }
  float triangle_area(std::uint32_t t) const {
    return 0.5f * length(cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0)));
  }
  Float3 transform_point(Float3 p) const {
    const auto& m = scene_.camera.camera_to_world;
    return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
            m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
  }
  Float3 transform_vector(Float3 v) const {
    const auto& m = scene_.camera.camera_to_world;
    return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
            m[8] * v.x + m[9] * v.y + m[10] * v.z};
  }

  // Ray origin pushed off the surface, to the side the ray leaves by.
  static Float3 offset(Float3 p, Float3 ng, Float3 wi) {
    const float scale = 2e-5f * (1 + std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}));
    return p + ng * (dot(ng, wi) > 0 ? scale : -scale);
  }

  static float mis_weight(float bsdf_pdf, float light_pdf) {
    return bsdf_pdf > 0 && light_pdf > 0 ? power_heuristic(bsdf_pdf, light_pdf) : 1.0f;
  }

  // Adds `radiance` (the path ending at an emitter) to every expression that
  // accepts the path closed by L.
  void add_emission(const std::vector<int>& states, std::vector<Float3>& sums, Float3 radiance, float weight) const {
    if (!(max_component(radiance) > 0)) return;
    for (std::size_t k = 0; k < dfas_.size(); ++k)
      if (dfas_[k].accepts(dfas_[k].step(states[k], LpeEvent::L))) sums[k] += radiance * weight;
  }

  // The surface point of a hit, normals on the viewer's side.
  SurfaceInput surface_input(const EmbreeScene::Hit& hit, Float3 origin, Float3 direction) const {
    const std::uint32_t t = hit.triangle;
    const float b1 = hit.u, b2 = hit.v, b0 = 1 - b1 - b2;
    SurfaceInput s;
    s.p = origin + direction * hit.t;
    s.wo = -direction;
    s.ng = normalize(cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0)));
    s.front = dot(s.ng, s.wo) > 0;
    s.n = s.ng;
    if (!scene_.normals.empty()) {
      const Float3* n = &scene_.normals[3 * std::size_t(t)];
      s.n = normalize(n[0] * b0 + n[1] * b1 + n[2] * b2);
    }
    if (!s.front) s.ng = -s.ng, s.n = -s.n;
    // Interpolated normals can face away from the viewer at silhouettes.
    if (dot(s.n, s.wo) <= 1e-4f) s.n = s.ng;
    s.u = s.v = 0;
    if (!scene_.uvs.empty()) {
      const auto* uv = &scene_.uvs[3 * std::size_t(t)];
      s.u = uv[0][0] * b0 + uv[1][0] * b1 + uv[2][0] * b2;
      s.v = uv[0][1] * b0 + uv[1][1] * b1 + uv[2][1] * b2;
    }
    return s;
  }

  // Adds the area lights the ray crosses from their emitting side within
  // (t_near, t_far). Lights are transparent, as in Cycles: rays go on behind
  // them, and they cast no shadows either.
  void add_area_lights_crossed(Float3 o, Float3 d, float t_near, float t_far, float travelled, unsigned kind,
                               Float3 throughput, float previous_pdf, const std::vector<int>& states,
                               std::vector<Float3>& sums) const {
    for (const Light& l : scene_.lights) {
      if (!(l.visibility & kind)) continue;
      if (!l.multiple_importance && kind != kVisibleCamera) continue;
      float t, pdf;
      Float3 radiance = l.radiance;
      if (l.type == Light::Type::area) {
        if (!cross_area_light(l, o, d, t_near, t_far, t, pdf)) continue;
        const float total = travelled + t;
        pdf *= (total * total) / (t * t);  // NEE measures from the scattering vertex
      } else if (l.type == Light::Type::point || l.type == Light::Type::spot) {
        // Measured from this segment's origin: exact unless a transparent surface came between.
        if (!cross_soft_light(l, o, d, t_near, t_far, t, pdf, radiance)) continue;
      } else {
        continue;
      }
      add_emission(states, sums, throughput * radiance, mis_weight(previous_pdf, pdf));
    }
  }

  bool sample_emissive_triangle(Float3 p, Rng& rng, LightSample& out) const {
    float probability;
    const std::size_t i = emissive_pick_.sample(rng.uniform(), probability);
    const std::uint32_t t = emissive_[i];
    const float r1 = std::sqrt(rng.uniform()), r2 = rng.uniform();
    const float b1 = r1 * (1 - r2), b2 = r1 * r2, b0 = 1 - b1 - b2;
    const Float3 x = corner(t, 0) * b0 + corner(t, 1) * b1 + corner(t, 2) * b2;
    Float3 n = normalize(cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0)));
    SurfaceInput at;
    at.p = x;
    at.wo = normalize(p - x);
    at.front = dot(n, at.wo) > 0;
    at.ng = at.front ? n : -n;
    at.n = at.ng;
    at.u = at.v = 0;
    if (!scene_.normals.empty()) {
      const Float3* ns = &scene_.normals[3 * std::size_t(t)];
      const Float3 shading = normalize(ns[0] * b0 + ns[1] * b1 + ns[2] * b2);
      at.n = at.front ? shading : -shading;
    }
    if (!scene_.uvs.empty()) {
      const auto* uv = &scene_.uvs[3 * std::size_t(t)];
      at.u = uv[0][0] * b0 + uv[1][0] * b1 + uv[2][0] * b2;
      at.v = uv[0][1] * b0 + uv[1][1] * b1 + uv[2][1] * b2;
    }
    const Float3 emission = emission_at(scene_, material(t), at);
    out.point = offset(x, n, p - x);  // so that the shadow ray cannot reach the emitter
    return to_area_sample(x - p, n, emission, triangle_light_pdf_[t], out, true);
  }

  // Fraction of light passing from `origin` along `wi` for `distance`:
  // 0 or 1, or the product of the transparent surfaces crossed.
  Float3 transmittance(Float3 origin, Float3 wi, float distance) const {
    if (!any_transparent_) return bvh_.occluded(origin, wi, distance) ? Float3{} : Float3{1, 1, 1};
    Float3 t{1, 1, 1};
    for (int crossed = 0;; ++crossed) {
      EmbreeScene::Hit hit{};
      if (!bvh_.intersect(origin, wi, 0, distance, hit, kVisibleShadow)) return t;
      if (crossed >= options_.transparent_bounces) return {};
      const SurfaceInput at = surface_input(hit, origin, wi);
      t *= transparency_at(scene_, material(hit.triangle), at);
      if (!(max_component(t) > 0)) return {};
      origin = offset(at.p, at.ng, wi);
      distance -= hit.t;
    }
  }

  // Next-event estimation at s, after `bounce` bounces: one sample per light
  // (one for all emissive triangles, one for a mapped world), each event's
  // lobes filed under it.
  void next_event(const ShadingPoint& s, Float3 throughput, int bounce, const std::vector<int>& states,
                  std::vector<Float3>& sums, Rng& rng) const {
    constexpr int kEvents = 3;
    const LpeEvent events[kEvents] = {LpeEvent::D, LpeEvent::S, LpeEvent::T};
    auto bucket = [](const Lobe& lobe) { return lobe.event() == LpeEvent::D ? 0 : lobe.event() == LpeEvent::S ? 1 : 2; };
    bool wanted[kEvents] = {false, false, false};
    bool any_lobe[kEvents] = {false, false, false};
    for (int i = 0; i < s.count; ++i)
      if (!s.lobes[i].singular() && s.lobes[i].pick > 0) any_lobe[bucket(s.lobes[i])] = true;
    for (int e = 0; e < kEvents; ++e)
      for (std::size_t k = 0; k < dfas_.size() && any_lobe[e] && !wanted[e]; ++k)
        wanted[e] = dfas_[k].accepts(dfas_[k].step(dfas_[k].step(states[k], events[e]), LpeEvent::L));
    if (!wanted[0] && !wanted[1] && !wanted[2]) return;

    auto shade_sample = [&](const LightSample& ls, unsigned light_visibility, bool shadows, bool mis) {
      Float3 f[kEvents];
      bool any = false;
      for (int i = 0; i < s.count; ++i) {
        const Lobe& lobe = s.lobes[i];
        const int e = bucket(lobe);
        if (lobe.singular() || !wanted[e]) continue;
        const unsigned needs = lobe.diffuse() ? kVisibleDiffuse : e == 1 ? kVisibleGlossy : kVisibleTransmission;
        if (!(light_visibility & needs)) continue;
        const LobeValue v = evaluate(s, lobe, ls.wi);
        if (v.pdf > 0) f[e] += v.f, any = true;
      }
      if (!any) return;
      const float bsdf_pdf = mis && ls.pdf > 0 ? mixture_pdf(s, ls.wi) : 0.0f;
      // Both ends are off their surfaces, so the segment between them can
      // only hit other geometry.
      const Float3 origin = offset(s.p, s.ng, ls.wi);
      Float3 pass{1, 1, 1};
      if (shadows) {
        if (std::isinf(ls.distance)) {
          pass = transmittance(origin, ls.wi, ls.distance);
        } else {
          const Float3 segment = ls.point - origin;
          const float span = length(segment);
          if (!(span > 0)) return;
          pass = transmittance(origin, segment / span, span);
        }
        if (!(max_component(pass) > 0)) return;
      }
      const float weight = ls.pdf > 0 && bsdf_pdf > 0 ? power_heuristic(ls.pdf, bsdf_pdf) : 1.0f;
      for (int e = 0; e < kEvents; ++e) {
        if (!(max_component(f[e]) > 0)) continue;
        const Float3 c = throughput * f[e] * ls.radiance * pass * weight;
        for (std::size_t k = 0; k < dfas_.size(); ++k)
          if (dfas_[k].accepts(dfas_[k].step(dfas_[k].step(states[k], events[e]), LpeEvent::L))) sums[k] += c;
      }
    };
    LightSample ls;
    for (const Light& l : scene_.lights) {
      const float u1 = rng.uniform(), u2 = rng.uniform();
      if (bounce > l.max_bounces) continue;  // drawn all the same: the other lights keep their numbers
      if (sample_light(l, s.p, u1, u2, ls)) shade_sample(ls, l.visibility, l.cast_shadow, l.multiple_importance);
    }
    if (!emissive_.empty() && sample_emissive_triangle(s.p, rng, ls)) shade_sample(ls, kVisibleAll, true, true);
    if (world_.sampled()) {
      const float u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform(), u4 = rng.uniform();
      if (world_.sample(u1, u2, u3, u4, ls)) shade_sample(ls, scene_.world_visibility, true, true);
    }
  }

  const Scene& scene_;
  const std::vector<LpeDfa>& dfas_;
  const TraceOptions& options_;
  EmbreeScene bvh_;
  Environment world_;
  FilterTable filter_;
  bool any_transparent_ = false;
  std::vector<std::uint32_t> emissive_;
  Distribution1D emissive_pick_;
  std::vector<float> triangle_light_pdf_;  // per triangle: pdf per area of NEE picking a point on it
};

}  // namespace

TraceResult trace_lpe(const Scene& scene, const std::vector<std::string>& expressions, const TraceOptions& options,
                      const TraceProgress& progress) {
  validate_fields(options, trace_option_table());
  if (!(options.filter_width > 0)) throw ValueError(concat("filter width must be above 0, got ", options.filter_width));
  std::vector<LpeDfa> dfas;
  for (const auto& e : expressions) dfas.push_back(compile_lpe(e, LpeOrder::eye_to_light));
  validate_scene(scene);

  const int width = scene.camera.width, height = scene.camera.height;
  TraceResult result;
  for (std::size_t k = 0; k < dfas.size(); ++k) result.images.emplace_back(width, height, 3);
  result.alpha = Image(width, height, 1);
  const Tracer tracer(scene, dfas, options);

  int rows_done = 0;
  std::mutex progress_mutex;
  parallel_for(height, options.threads, [&](int y) {
    std::vector<int> states(dfas.size());
    std::vector<Float3> sums(dfas.size());
    for (int x = 0; x < width; ++x) {
      const std::uint64_t pixel = std::uint64_t(y) * std::uint64_t(width) + std::uint64_t(x);
      Rng pixel_rng(mix64(options.seed), pixel);  // a seed of its own: no stream shared with paths
      const std::uint32_t scramble_x = std::uint32_t(pixel_rng.next()), scramble_y = std::uint32_t(pixel_rng.next());
      std::fill(sums.begin(), sums.end(), Float3{});
      float alpha = 0;
      for (int i = 0; i < options.samples; ++i) {
        Rng rng(options.seed, pixel * kMaxTraceSamples + std::uint64_t(i));
        tracer.trace_sample(x, y, std::uint32_t(i), scramble_x, scramble_y, rng, states, sums, alpha);
      }
      const float inv = 1.0f / float(options.samples);
      for (std::size_t k = 0; k < dfas.size(); ++k) {
        float* out = result.images[k].pixel(x, y);
        out[0] = sums[k].x * inv, out[1] = sums[k].y * inv, out[2] = sums[k].z * inv;
      }
      result.alpha.at(x, y, 0) = alpha * inv;
    }
    if (progress) {
      // Counted under the lock so that reports never go backwards.
      std::lock_guard lock(progress_mutex);
      if (!progress(double(++rows_done) / height)) throw CancelledError("tracing cancelled");
    }
  });
  return result;
}

}  // namespace tempera

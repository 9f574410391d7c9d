#pragma once
// Light sampling as Cycles does it: point and spot lights with a radius
// (a disk facing the shaded point, or a sphere), the spot cone with its
// smoothstep blend and Cycles 3.x's extra cosine to the axis, suns with an angular
// diameter, one-sided rectangle and ellipse area lights, and the world: a
// constant colour or an importance-sampled equirectangular environment.
#include <vector>

#include "sampling.hpp"
#include "tempera/tracer/scene.hpp"

namespace tempera::tracer {

struct LightSample {
  Float3 wi;
  float distance = 0;   // to the sampled point (infinite for the sun and the world)
  Float3 point;         // the sampled point (finite lights)
  Float3 radiance;      // incoming radiance divided by the sample's pdf
  float pdf = 0;        // solid angle; 0 for lights BSDF rays cannot hit
};

// One sample of light `l` as seen from p; false if it cannot light p.
bool sample_light(const Light& l, Float3 p, float u1, float u2, LightSample& out);

float area_of(const Light& l);

// Where the ray (o, d) crosses area light l from its emitting side within
// (t_near, t_far): its distance, and the pdf (solid angle) of NEE choosing it.
bool cross_area_light(const Light& l, Float3 o, Float3 d, float t_near, float t_far, float& t, float& pdf);

// Where the ray (o, d) hits the disk (or sphere) of a point or spot light
// with a radius, within (t_near, t_far): distance, NEE pdf (solid angle)
// and radiance (spot attenuation included). Cycles' soft lights are
// reachable by BSDF rays.
bool cross_soft_light(const Light& l, Float3 o, Float3 d, float t_near, float t_far, float& t, float& pdf,
                      Float3& radiance);

// Converts a point sampled on an emitting surface (pdf per area) to a
// direction sample; one-sided unless two_sided.
bool to_area_sample(Float3 to_x, Float3 normal, Float3 radiance, float pdf_area, LightSample& out,
                    bool two_sided = false);

// The world's radiance, and its importance sampling when it has a map.
class Environment {
 public:
  explicit Environment(const Scene& scene);
  Float3 radiance(Float3 direction) const;
  bool sampled() const { return !rows_.empty(); }  // constant worlds are left to BSDF sampling
  bool sample(float u1, float u2, float u3, float u4, LightSample& out) const;
  float pdf(Float3 direction) const;

 private:
  Float3 to_map(Float3 d) const;
  const Scene& scene_;
  const Image* map_ = nullptr;
  Distribution1D rows_;
  std::vector<Distribution1D> columns_;
};

}  // namespace tempera::tracer

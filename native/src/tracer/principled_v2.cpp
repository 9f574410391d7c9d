#include "principled_v2.hpp"

#include <algorithm>
#include <cmath>

#include "microfacet_albedo.hpp"

namespace tempera::tracer {
namespace {

constexpr float kWeightCutoff = 1e-5f;  // layers lighter than this are left out (Cycles' closure cutoff)

Float3 clamp01(Float3 v) {
  return {std::clamp(v.x, 0.0f, 1.0f), std::clamp(v.y, 0.0f, 1.0f), std::clamp(v.z, 0.0f, 1.0f)};
}
Float3 max0(Float3 v) { return {std::max(v.x, 0.0f), std::max(v.y, 0.0f), std::max(v.z, 0.0f)}; }
Float3 mix(Float3 a, Float3 b, float t) { return a + (b - a) * t; }
float f0_from_ior(float ior) {
  const float r = (ior - 1) / (ior + 1);
  return r * r;
}
float ior_from_f0(float f0) {
  const float r = std::sqrt(std::clamp(f0, 0.0f, 0.9999f));
  return (1 + r) / (1 - r);
}

// What a layer of directional albedo `albedo` (relative to the weight reaching
// it) passes down: the weight times 1 - its largest channel.
Float3 below_layer(Float3 weight, Float3 albedo) {
  return weight * std::clamp(1 - max_component(albedo), 0.0f, 1.0f);
}

// What passes through the coat is tinted by Beer's law along the refracted
// view ray, tint^(1/cos_t), in proportion to the coat's weight.
Float3 coat_tint(const Closure& c, Float3 weight, float mu) {
  const float coat = std::max(c.clearcoat, 0.0f);
  const Float3 tint = max0(c.coat_tint);
  if (coat <= kWeightCutoff || (tint.x == 1 && tint.y == 1 && tint.z == 1)) return weight;
  const float ior = std::max(c.coat_ior, 1.0f);
  const float cos_t = std::sqrt(std::max(1e-6f, 1 - (1 - mu * mu) / (ior * ior)));
  const Float3 through{std::pow(tint.x, 1 / cos_t), std::pow(tint.y, 1 / cos_t), std::pow(tint.z, 1 / cos_t)};
  return weight * mix({1, 1, 1}, through, std::min(coat, 1.0f));
}

// Coat: a GGX dielectric layer of its own IOR and roughness, then its tint.
Float3 add_coat(ShadingPoint& s, const Closure& c, Float3 weight, float mu) {
  const float coat = std::max(c.clearcoat, 0.0f);
  if (coat <= kWeightCutoff) return weight;
  const float roughness = std::clamp(c.clearcoat_roughness, 0.0f, 1.0f);
  const float ior = std::max(c.coat_ior, 1.0f);
  Lobe l = reflection_lobe(weight * coat, roughness, false, FresnelMode::dielectric, {});
  l.eta = ior;
  add_lobe(s, l);
  const float albedo = coat * (f0_from_ior(ior) + (1 - f0_from_ior(ior)) * ggx_fresnel_blend(roughness, mu, ior));
  return coat_tint(c, below_layer(weight, {albedo, albedo, albedo}), mu);
}

// Multiscatter GGX's compensation of a lobe whose hemispherical mean Fresnel is f_ss.
Float3 multiscatter(float roughness, float mu, Float3 f_ss) {
  return {multiscatter_factor(roughness, mu, f_ss.x), multiscatter_factor(roughness, mu, f_ss.y),
          multiscatter_factor(roughness, mu, f_ss.z)};
}

void add_metal(ShadingPoint& s, const Closure& c, Float3 weight, Float3 base, float roughness, float mu) {
  const Float3 f0 = clamp01(base);
  Lobe l = reflection_lobe(weight, roughness, false, FresnelMode::f82, f0);
  l.f82_b = f82_tint_b(f0, clamp01(max0(c.specular_tint)));
  // The hemispherical mean of the F82 Fresnel: f0 + (1 - f0) / 21 - b / 126.
  if (c.multiscatter) l.weight *= multiscatter(roughness, mu, mix(f0, {1, 1, 1}, 1.0f / 21) - l.f82_b * (1.0f / 126));
  add_lobe(s, l);
}

// The dielectric specular layer: F0 from the IOR, times 2 x Specular IOR Level
// (the IOR is then the one of that F0) and Specular Tint, rising to 1 at grazing
// angles like the dielectric Fresnel of that IOR. Returns the weight below it.
Float3 add_specular(ShadingPoint& s, const Closure& c, Float3 weight, float roughness, float mu) {
  const float ior = std::max(c.ior, 1e-5f);
  float eta = ior, f0 = f0_from_ior(ior);
  const float level = std::max(c.specular_ior_level, 0.0f);
  if (level != 0.5f) {
    f0 = std::min(f0 * 2 * level, 0.9999f);
    eta = ior_from_f0(f0);
    if (ior < 1) eta = 1 / eta;
  }
  if (eta == 1) return weight;
  const Float3 tinted_f0 = max0(c.specular_tint) * f0;
  Lobe l = reflection_lobe(weight, roughness, false, FresnelMode::principled, tinted_f0);
  l.eta = eta;
  Float3 albedo = mix(tinted_f0, {1, 1, 1}, ggx_fresnel_blend(roughness, mu, eta));
  if (c.multiscatter) {
    const float f0_eta = f0_from_ior(eta);
    const float blend = std::clamp((dielectric_average_fresnel(eta) - f0_eta) / (1 - f0_eta), 0.0f, 1.0f);
    const Float3 f_ss = mix(tinted_f0, {1, 1, 1}, blend);
    const Float3 factor = multiscatter(roughness, mu, f_ss);
    l.weight *= factor;
    // Cycles counts the compensated lobe's albedo as E times the factor.
    albedo *= factor * ggx_albedo(roughness, mu);
  }
  add_lobe(s, l);
  return below_layer(weight, albedo);
}

// Transmission: glass whose reflection (F of each microfacet) is untinted
// and whose refraction (1 - F) is tinted by sqrt(base colour), as Cycles 4
// splits them; rough glass is one microfacet closure, smooth glass singular.
void add_transmission(ShadingPoint& s, const Closure& c, Float3 weight, Float3 base, float roughness) {
  const float eta = s.front ? std::max(c.ior, 1e-5f) : 1 / std::max(c.ior, 1e-5f);
  const Float3 b = clamp01(base);
  const Float3 refracted = weight * Float3{std::sqrt(b.x), std::sqrt(b.y), std::sqrt(b.z)};
  if (roughness >= kSingularRoughness) {
    Lobe reflection = reflection_lobe(weight, roughness, false, FresnelMode::dielectric, {});
    reflection.eta = eta;
    add_lobe(s, reflection);
    Lobe t = reflection_lobe(refracted, roughness, false, FresnelMode::dielectric, {});
    t.kind = LobeKind::microfacet_transmission;
    t.eta = eta;
    add_lobe(s, t);
    return;
  }
  Lobe glass;  // two singular parts, each with its own tint and its share F or 1 - F
  glass.kind = LobeKind::dielectric;
  glass.eta = eta;
  glass.fresnel = FresnelMode::dielectric;
  glass.weight = weight;
  glass.refract = false;
  add_lobe(s, glass);
  glass.weight = refracted;
  glass.reflect = false;
  glass.refract = true;
  add_lobe(s, glass);
}

}  // namespace

Float3 fresnel_f82(Float3 f0, Float3 b, float cos_theta) {
  const float c = std::clamp(cos_theta, 0.0f, 1.0f), m = 1 - c;
  const float m5 = m * m * m * m * m;
  return clamp01(f0 + (Float3{1, 1, 1} - f0) * m5 - b * (c * m5 * m));
}

Float3 f82_tint_b(Float3 f0, Float3 tint) {
  constexpr float kCos = 1.0f / 7, kM = 1 - kCos;
  const float m5 = kM * kM * kM * kM * kM;
  const Float3 schlick = f0 + (Float3{1, 1, 1} - f0) * m5;
  return schlick * (Float3{1, 1, 1} - tint) * (1 / (kCos * m5 * kM));
}

void add_principled_v2(ShadingPoint& s, const Closure& c, Float3 weight, Float3 base, float roughness) {
  const float mu = std::clamp(dot(s.n, s.wo), 0.0f, 1.0f);
  base = max0(base);
  // `unlayered`: the weight without the reflective layers' 1 - albedo (see Lobe::layered).
  Float3 unlayered = coat_tint(c, weight, mu);
  weight = add_coat(s, c, weight, mu);
  const float metallic = std::clamp(c.metallic, 0.0f, 1.0f);
  if (metallic > kWeightCutoff) {
    add_metal(s, c, weight * metallic, base, roughness, mu);
    weight = weight * (1 - metallic);
    unlayered = unlayered * (1 - metallic);
  }
  const float transmission = std::clamp(c.transmission, 0.0f, 1.0f);
  if (transmission > kWeightCutoff) {
    add_transmission(s, c, weight * transmission, base, roughness);
    weight = weight * (1 - transmission);
    unlayered = unlayered * (1 - transmission);
  }
  weight = add_specular(s, c, weight, roughness, mu);
  Lobe diffuse;  // Lambertian; subsurface scattering is traced as this diffuse reflection
  diffuse.kind = LobeKind::lambert;
  diffuse.weight = weight * base;
  diffuse.layered = true;
  diffuse.unlayered_weight = unlayered * base;
  add_lobe(s, diffuse);
}

}  // namespace tempera::tracer

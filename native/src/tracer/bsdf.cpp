#include "bsdf.hpp"

#include "principled_v2.hpp"

#include <algorithm>
#include <cmath>

namespace tempera::tracer {
namespace {


Float3 schlick(Float3 f0, float cos_theta) {
  const float m = 1 - std::clamp(cos_theta, 0.0f, 1.0f);
  const float m5 = m * m * m * m * m;
  return f0 + (Float3{1, 1, 1} - f0) * m5;
}

float ggx_d(float cos_h, float alpha2) {
  // sin^2 + cos^2 alpha^2 rather than cos^2 (alpha^2 - 1) + 1, which rounds to 0
  // at the peak of a nearly smooth surface.
  const float c2 = cos_h * cos_h;
  const float d = std::max(0.0f, 1 - c2) + c2 * alpha2;
  return alpha2 / (kPi * d * d);
}
float ggx_g1(float cos_v, float alpha2) {
  const float c2 = cos_v * cos_v;
  return 2 / (1 + std::sqrt(1 + alpha2 * (1 - c2) / c2));
}
float beckmann_d(float cos_h, float alpha2) {
  const float c2 = cos_h * cos_h;
  return std::exp((c2 - 1) / (c2 * alpha2)) / (kPi * alpha2 * c2 * c2);
}
float beckmann_g1(float cos_v, float alpha2) {  // Walter et al. 2007's rational fit
  const float sin_v = std::sqrt(std::fmax(0.0f, 1 - cos_v * cos_v));
  if (sin_v <= 0) return 1;
  const float a = cos_v / (std::sqrt(alpha2) * sin_v);
  if (a >= 1.6f) return 1;
  return (3.535f * a + 2.181f * a * a) / (1 + 2.276f * a + 2.577f * a * a);
}

// Smith's Lambda (Heitz 2014): G1 = 1 / (1 + Lambda). GGX's is exact; Beckmann's
// is Walter et al. 2007's rational fit, the one beckmann_g1 uses.
float ggx_lambda(float cos_v, float alpha2) {
  const float c2 = cos_v * cos_v;
  return 0.5f * (std::sqrt(1 + alpha2 * (1 - c2) / c2) - 1);
}
float beckmann_lambda(float cos_v, float alpha2) {
  const float sin_v = std::sqrt(std::fmax(0.0f, 1 - cos_v * cos_v));
  if (sin_v <= 0) return 0;
  const float a = cos_v / (std::sqrt(alpha2) * sin_v);
  if (a >= 1.6f) return 0;
  return (1 - 1.259f * a + 0.396f * a * a) / (3.535f * a + 2.181f * a * a);
}

// Masking-shadowing of a microfacet lobe for |cos| to wi and wo: separable
// G1(i) G1(o) (Cycles 3.x) or height-correlated 1 / (1 + Lambda(i) + Lambda(o))
// (Cycles 4.0+), which is larger: less energy lost at grazing angles.
float smith_g(const Lobe& l, float cos_i, float cos_o) {
  if (l.correlated) {
    const float li = l.beckmann ? beckmann_lambda(cos_i, l.alpha2) : ggx_lambda(cos_i, l.alpha2);
    const float lo = l.beckmann ? beckmann_lambda(cos_o, l.alpha2) : ggx_lambda(cos_o, l.alpha2);
    return 1 / (1 + li + lo);
  }
  return l.beckmann ? beckmann_g1(cos_i, l.alpha2) * beckmann_g1(cos_o, l.alpha2)
                    : ggx_g1(cos_i, l.alpha2) * ggx_g1(cos_o, l.alpha2);
}

// Cycles' Fresnel and Layer Weight nodes at the shading point.
float factor_value(const Scene& scene, const Factor& f, const SurfaceInput& at) {
  float x = 1;
  const float cos_o = std::fabs(dot(at.wo, at.n));
  switch (f.kind) {
    case Factor::Kind::constant: x = f.value; break;
    case Factor::Kind::texture: x = texture_scalar(scene, f.texture, at.u, at.v); break;
    case Factor::Kind::fresnel: {
      const float eta = std::max(f.value, 1e-5f);
      x = fresnel_dielectric(cos_o, at.front ? eta : 1 / eta);
      break;
    }
    case Factor::Kind::layer_fresnel: {
      const float eta = std::max(1 - f.value, 1e-5f);
      x = fresnel_dielectric(cos_o, at.front ? 1 / eta : eta);
      break;
    }
    case Factor::Kind::layer_facing: {
      float blend = f.value;
      x = cos_o;
      if (blend != 0.5f) {
        blend = std::clamp(blend, 0.0f, 1 - 1e-5f);
        blend = blend < 0.5f ? 2 * blend : 0.5f / (1 - blend);
        x = std::pow(x, blend);
      }
      x = 1 - x;
      break;
    }
  }
  x = std::clamp(x, 0.0f, 1.0f);
  return f.invert ? 1 - x : x;
}

Float3 closure_weight(const Scene& scene, const Closure& c, const SurfaceInput& at) {
  float w = 1;
  for (const Factor& f : c.factors) w *= factor_value(scene, f, at);
  return c.weight * w;
}

Float3 closure_color(const Scene& scene, const Closure& c, const SurfaceInput& at) {
  return c.color_texture.valid() ? texture_rgb(scene, c.color_texture, at.u, at.v) : c.color;
}

float closure_roughness(const Scene& scene, const Closure& c, const SurfaceInput& at) {
  const float r = c.roughness_texture.valid() ? texture_scalar(scene, c.roughness_texture, at.u, at.v) : c.roughness;
  return std::clamp(r, 0.0f, 1.0f);
}

// Cycles 3.x's Principled Fresnel: the dielectric Fresnel of `eta`, remapped
// so that it starts at f0 (the specular colour) at normal incidence.
Float3 principled_fresnel(const Lobe& l, float cos_theta) {
  const float normal = fresnel_dielectric(1, l.eta);
  const float t = (fresnel_dielectric(cos_theta, l.eta) - normal) / (1 - normal);
  return l.f0 + (Float3{1, 1, 1} - l.f0) * t;
}

void add_principled(ShadingPoint& s, Float3 weight, Float3 base, float metallic, float specular, float roughness,
                    float transmission, float ior) {
  metallic = std::clamp(metallic, 0.0f, 1.0f);
  transmission = std::clamp(transmission, 0.0f, 1.0f);
  const float specular_f0 = 0.08f * std::max(specular, 0.0f);
  const Float3 f0 = Float3{specular_f0, specular_f0, specular_f0} * (1 - metallic) + base * metallic;
  Lobe diffuse;
  diffuse.kind = LobeKind::principled_diffuse;
  diffuse.a = roughness;
  diffuse.weight = weight * base * ((1 - metallic) * (1 - transmission));
  add_lobe(s, diffuse);
  Lobe specular_lobe = reflection_lobe(weight * (1 - (1 - metallic) * transmission), roughness, false,
                                       FresnelMode::principled, f0);
  // Cycles derives the specular lobe's IOR from Specular (0.5 -> 1.5).
  specular_lobe.eta = 2 / (1 - std::sqrt(std::clamp(0.08f * specular, 0.0f, 0.99f))) - 1;
  add_lobe(s, specular_lobe);
  Lobe glass;
  glass.kind = LobeKind::dielectric;
  glass.weight = weight * base * ((1 - metallic) * transmission);
  glass.eta = s.front ? ior : 1 / ior;
  glass.fresnel = FresnelMode::dielectric;
  add_lobe(s, glass);
}

// Directional albedo of Fujii's single-scattering Oren-Nayar with constants
// a, b, lit or seen at cos_theta: a pi + b G(theta), G in closed form (as the
// OpenPBR specification gives it), its limit near grazing below 1e-6.
float oren_nayar_albedo(float a, float b, float cos_theta) {
  float g;
  if (cos_theta < 1e-6f) {
    g = (kPi / 2 - 2.0f / 3) - cos_theta;
  } else {
    const float sin_t = std::sqrt(std::max(0.0f, 1 - cos_theta * cos_theta));
    const float theta = std::acos(std::min(cos_theta, 1.0f));
    g = sin_t * (theta - 2.0f / 3 - sin_t * cos_theta) +
        (2.0f / 3) * (sin_t / cos_theta) * (1 - sin_t * sin_t * sin_t);
  }
  return a * kPi + b * g;
}

// Cycles 4.3's Diffuse BSDF with a roughness: Fujii's form with the constants
// a = 1 / (pi + sigma (pi/2 - 2/3)), b = sigma a, plus OpenPBR's multiple
// scattering, which returns what single scattering loses: E_ms (1 - E(wo))
// (1 - E(wi)), E_ms from the colour and the average albedo E_avg. The part
// that depends on the viewer is fixed here; evaluate() adds 1 - E(wi).
void energy_preserving_oren_nayar(Lobe& l, float sigma, Float3 color, float cos_v) {
  l.kind = LobeKind::oren_nayar;
  l.a = 1 / (kPi + sigma * (kPi / 2 - 2.0f / 3));
  l.b = sigma * l.a;
  const float e_avg = l.a * kPi + ((2 * kPi - 5.6f) / 3) * l.b;
  const float seen = 1 - oren_nayar_albedo(l.a, l.b, cos_v);
  auto multiple = [&](float albedo) {
    albedo = std::clamp(albedo, 0.0f, 1.0f);
    return albedo * albedo * (e_avg / (1 - e_avg)) / (kPi * (1 - albedo * (1 - e_avg))) * seen;
  };
  l.multiscatter = {multiple(color.x), multiple(color.y), multiple(color.z)};
}

void add_closure(const Scene& scene, ShadingPoint& s, const Closure& c, const SurfaceInput& at) {
  const Float3 weight = closure_weight(scene, c, at);
  if (!(max_component(weight) > 0)) return;
  const Float3 color = closure_color(scene, c, at);
  switch (c.type) {
    case Closure::Type::principled: {
      if (scene.closure_model.principled_v2) {
        add_principled_v2(s, c, weight, color, closure_roughness(scene, c, at));
        break;
      }
      const float ss = std::clamp(c.subsurface, 0.0f, 1.0f);
      add_principled(s, weight, color * (1 - ss) + c.subsurface_color * ss, c.metallic, c.specular,
                     closure_roughness(scene, c, at), c.transmission, c.ior);
      if (c.clearcoat > 0) {
        const float r = std::clamp(c.clearcoat_roughness, 0.0f, 1.0f);
        Lobe coat = reflection_lobe(weight * (0.25f * c.clearcoat), r, false, FresnelMode::principled,
                                    {0.04f, 0.04f, 0.04f});
        coat.eta = 1.5f;
        add_lobe(s, coat);
      }
      break;
    }
    case Closure::Type::diffuse: {
      Lobe l;
      l.weight = weight * color;
      const float sigma = closure_roughness(scene, c, at);
      if (sigma > 0 && scene.closure_model.energy_preserving_oren_nayar) {
        energy_preserving_oren_nayar(l, sigma, color, std::max(dot(s.n, s.wo), 0.0f));
      } else if (sigma > 0) {  // Cycles 3.x's Oren-Nayar (Fujii's form), roughness as sigma
        l.kind = LobeKind::oren_nayar;
        const float div = 1 / (kPi + ((3 * kPi - 4) / 6) * sigma);
        l.a = div;
        l.b = sigma * div;
      }
      add_lobe(s, l);
      break;
    }
    case Closure::Type::translucent: {
      Lobe l;
      l.kind = LobeKind::translucent;
      l.weight = weight * color;
      add_lobe(s, l);
      break;
    }
    case Closure::Type::glossy: {
      const bool sharp = c.distribution == Closure::Distribution::sharp;
      Lobe l = reflection_lobe(weight * color, sharp ? 0.0f : closure_roughness(scene, c, at),
                               c.distribution == Closure::Distribution::beckmann, FresnelMode::none, {});
      l.sharp = sharp;
      add_lobe(s, l);
      break;
    }
    case Closure::Type::glass:
    case Closure::Type::refraction: {
      const float r = c.distribution == Closure::Distribution::sharp ? 0.0f : closure_roughness(scene, c, at);
      if (r >= kSingularRoughness) {
        // Rough glass as Cycles 3.x builds it: a microfacet reflection weighted
        // by the Fresnel of the shading normal, and a microfacet refraction by
        // the rest (Refraction BSDF: the refraction alone, unweighted).
        // Cycles 4.0+ (microfacet_glass_fresnel): one closure whose parts take
        // the Fresnel of each microfacet normal, F(h) and 1 - F(h).
        const float eta = s.front ? c.ior : 1 / c.ior;
        const bool is_glass = c.type == Closure::Type::glass;
        const bool per_microfacet = is_glass && scene.closure_model.microfacet_glass_fresnel;
        const float fresnel = is_glass && !per_microfacet ? fresnel_dielectric(dot(at.n, at.wo), eta) : 0.0f;
        const bool beckmann = c.distribution == Closure::Distribution::beckmann;
        const FresnelMode mode = per_microfacet ? FresnelMode::dielectric : FresnelMode::none;
        if (per_microfacet || fresnel > 0) {
          Lobe reflection = reflection_lobe(weight * color * (per_microfacet ? 1.0f : fresnel), r, beckmann, mode, {});
          reflection.eta = eta;
          add_lobe(s, reflection);
        }
        Lobe t = reflection_lobe(weight * color * (1 - fresnel), r, beckmann, mode, {});
        t.kind = LobeKind::microfacet_transmission;
        t.eta = eta;
        add_lobe(s, t);
        break;
      }
      Lobe l;
      l.kind = LobeKind::dielectric;
      l.weight = weight * color;
      l.eta = s.front ? c.ior : 1 / c.ior;
      l.reflect = c.type == Closure::Type::glass;
      l.fresnel = c.type == Closure::Type::glass ? FresnelMode::dielectric : FresnelMode::none;
      add_lobe(s, l);
      break;
    }
    case Closure::Type::transparent: s.transparency += weight * color; break;
    case Closure::Type::emission: s.emission += weight * color; break;
  }
}

float lobe_energy(const ShadingPoint& s, const Lobe& l) {
  if (l.fresnel == FresnelMode::dielectric && !l.singular()) {  // microfacet glass: F and 1 - F at the normal
    const float f = fresnel_dielectric(dot(s.n, s.wo), l.eta);
    return luminance(l.weight) * (l.kind == LobeKind::microfacet_transmission ? 1 - f : f);
  }
  if (l.fresnel == FresnelMode::schlick) return luminance(l.weight * schlick(l.f0, dot(s.n, s.wo)));
  if (l.fresnel == FresnelMode::principled) return luminance(l.weight * principled_fresnel(l, dot(s.n, s.wo)));
  if (l.fresnel == FresnelMode::f82) return luminance(l.weight * fresnel_f82(l.f0, l.f82_b, dot(s.n, s.wo)));
  if (l.fresnel == FresnelMode::dielectric && l.kind == LobeKind::mirror)  // a smooth coat
    return luminance(l.weight) * fresnel_dielectric(dot(s.n, s.wo), l.eta);
  return luminance(l.weight);
}

void set_picks(ShadingPoint& s) {
  float energy[kMaxLobes], total = 0;
  for (int i = 0; i < s.count; ++i) total += energy[i] = std::max(lobe_energy(s, s.lobes[i]), 0.0f);
  const float transparent = std::max(luminance(s.transparency), 0.0f);
  total += transparent;
  for (int i = 0; i < s.count; ++i) s.lobes[i].pick = total > 0 ? energy[i] / total : 0;
  s.pick_transparent = total > 0 ? transparent / total : 0;
}

ShadingPoint start(const SurfaceInput& at) {
  ShadingPoint s;
  s.p = at.p, s.n = at.n, s.ng = at.ng, s.wo = at.wo, s.front = at.front;
  return s;
}

}  // namespace

void add_lobe(ShadingPoint& s, const Lobe& lobe) {
  if (s.count < kMaxLobes && max_component(lobe.weight) > 0) s.lobes[s.count++] = lobe;
}

Lobe reflection_lobe(Float3 weight, float roughness, bool beckmann, FresnelMode fresnel, Float3 f0) {
  Lobe l;
  l.kind = roughness < kSingularRoughness ? LobeKind::mirror : LobeKind::microfacet;
  l.weight = weight;
  l.alpha2 = std::max(roughness * roughness * roughness * roughness, 1e-8f);
  l.beckmann = beckmann;
  l.fresnel = fresnel;
  l.f0 = f0;
  return l;
}

float fresnel_dielectric(float cos_i, float eta) {
  cos_i = std::fabs(cos_i);
  const float sin_t2 = (1 - cos_i * cos_i) / (eta * eta);
  if (sin_t2 >= 1) return 1;
  const float cos_t = std::sqrt(1 - sin_t2);
  const float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

ShadingPoint shade(const Scene& scene, const Material& m, const SurfaceInput& at) {
  ShadingPoint s = start(at);
  if (m.closures.empty()) {
    add_principled(s, {1, 1, 1}, base_color_at(m, at.u, at.v), m.metallic, m.specular,
                   std::clamp(m.roughness, 0.0f, 1.0f), m.transmission, m.ior);
    s.emission = m.emission;
  } else {
    for (const Closure& c : m.closures) add_closure(scene, s, c, at);
  }
  for (int i = 0; i < s.count; ++i) s.lobes[i].correlated = scene.closure_model.height_correlated_shadowing;
  set_picks(s);
  return s;
}

Float3 emission_at(const Scene& scene, const Material& m, const SurfaceInput& at) {
  if (m.closures.empty()) return m.emission;
  Float3 e;
  for (const Closure& c : m.closures)
    if (c.type == Closure::Type::emission) e += closure_weight(scene, c, at) * closure_color(scene, c, at);
  return e;
}

Float3 transparency_at(const Scene& scene, const Material& m, const SurfaceInput& at) {
  Float3 t;
  for (const Closure& c : m.closures)
    if (c.type == Closure::Type::transparent) t += closure_weight(scene, c, at) * closure_color(scene, c, at);
  return t;
}

bool has_transparency(const Material& m) {
  for (const Closure& c : m.closures)
    if (c.type == Closure::Type::transparent) return true;
  return false;
}

Float3 constant_emission(const Material& m) {
  if (m.closures.empty()) return m.emission;
  Float3 e;
  for (const Closure& c : m.closures) {
    if (c.type != Closure::Type::emission) continue;
    // Textured or view-dependent weights: their constant part stands for them (only the pick uses it).
    e += c.weight * (c.color_texture.valid() ? Float3{1, 1, 1} : c.color);
  }
  return e;
}

void filter_caustics(ShadingPoint& s, bool reflective, bool refractive) {
  if (reflective && refractive) return;
  int kept = 0;
  for (int i = 0; i < s.count; ++i) {
    Lobe l = s.lobes[i];
    if (l.kind == LobeKind::microfacet || l.kind == LobeKind::mirror) {
      if (!reflective) continue;
    } else if (l.layered && !reflective) {
      l.weight = l.unlayered_weight;
    } else if (l.kind == LobeKind::microfacet_transmission) {
      if (!refractive) continue;
    } else if (l.kind == LobeKind::dielectric) {
      l.reflect &= reflective;
      l.refract &= refractive;
      if (!l.reflect && !l.refract) continue;
    }
    s.lobes[kept++] = l;
  }
  s.count = kept;
  set_picks(s);
}

LobeValue evaluate_lobe(const ShadingPoint& s, const Lobe& l, Float3 wi);

void blur_glossy(ShadingPoint& s, float alpha) {
  const float alpha2 = alpha * alpha;
  for (int i = 0; i < s.count; ++i) {
    Lobe& l = s.lobes[i];
    const bool blurrable = l.kind == LobeKind::microfacet || l.kind == LobeKind::microfacet_transmission ||
                           (l.kind == LobeKind::mirror && !l.sharp);
    if (!blurrable || l.alpha2 >= alpha2) continue;
    l.alpha2 = alpha2;
    if (l.kind == LobeKind::mirror) l.kind = LobeKind::microfacet;
  }
}

bool finite3(Float3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Degenerate half vectors of nearly smooth lobes can overflow: such values are dropped.
LobeValue evaluate(const ShadingPoint& s, const Lobe& l, Float3 wi) {
  const LobeValue v = evaluate_lobe(s, l, wi);
  if (!finite3(v.f) || !std::isfinite(v.pdf)) return {};
  return v;
}

LobeValue evaluate_lobe(const ShadingPoint& s, const Lobe& l, Float3 wi) {
  if (l.pick <= 0 || l.singular()) return {};
  const float cos_i = dot(s.n, wi);
  if (l.kind == LobeKind::translucent) {
    if (cos_i >= 0 || dot(s.ng, wi) >= 0) return {};
    return {l.weight * (-cos_i / kPi), -cos_i / kPi};
  }
  if (l.kind == LobeKind::microfacet_transmission) {
    const float cos_o = dot(s.n, s.wo);
    if (cos_i >= 0 || dot(s.ng, wi) >= 0 || cos_o <= 0) return {};
    // The refraction half vector, on the shading normal's side.
    Float3 h = -(s.wo + wi * l.eta);
    const float len = length(h);
    if (!(len > 0)) return {};
    h = h / len;
    if (dot(h, s.n) < 0) h = -h;
    const float cos_ho = dot(h, s.wo), cos_hi = dot(h, wi);
    if (cos_ho <= 0 || cos_hi >= 0) return {};
    const float cos_h = dot(s.n, h);
    const float d = l.beckmann ? beckmann_d(cos_h, l.alpha2) : ggx_d(cos_h, l.alpha2);
    const float g = smith_g(l, -cos_i, cos_o);
    const float denom = cos_ho + l.eta * cos_hi;
    const float jacobian = l.eta * l.eta * -cos_hi / (denom * denom);  // d(omega_h) / d(omega_i)
    // Radiance is not rescaled by eta^2 (as in Cycles).
    const float transmitted = l.fresnel == FresnelMode::dielectric ? 1 - fresnel_dielectric(cos_ho, l.eta) : 1.0f;
    return {l.weight * (d * g * cos_ho * jacobian * transmitted / cos_o), d * cos_h * jacobian};
  }
  if (cos_i <= 0 || dot(s.ng, wi) <= 0) return {};
  if (l.kind == LobeKind::lambert) return {l.weight * (cos_i / kPi), cos_i / kPi};
  if (l.kind == LobeKind::oren_nayar) {
    const float cos_v = std::max(dot(s.n, s.wo), 0.0f);
    float t = dot(wi, s.wo) - cos_i * cos_v;
    if (t > 0) t /= std::max(cos_i, cos_v) + 1e-30f;
    if (max_component(l.multiscatter) > 0) {  // what the single scattering loses towards wi, returned
      const Float3 multi = l.multiscatter * (1 - oren_nayar_albedo(l.a, l.b, cos_i));
      return {l.weight * (Float3{1, 1, 1} * (l.a + l.b * t) + multi) * cos_i, cos_i / kPi};
    }
    return {l.weight * (cos_i * (l.a + l.b * t)), cos_i / kPi};
  }
  if (l.kind == LobeKind::principled_diffuse) {
    // Disney's diffuse as Cycles 3.x's Principled BSDF has it: Fresnel-shaped
    // darkening at grazing angles plus roughness-driven retro-reflection.
    const float cos_v = std::max(dot(s.n, s.wo), 0.0f);
    auto schlick_weight = [](float c) {
      const float m = std::clamp(1 - c, 0.0f, 1.0f);
      return m * m * m * m * m;
    };
    const float fl = schlick_weight(cos_i), fv = schlick_weight(cos_v);
    const Float3 h = normalize(wi + s.wo);
    const float cos_lh = dot(wi, h);
    const float rr = 2 * l.a * cos_lh * cos_lh;
    const float value = (1 - 0.5f * fl) * (1 - 0.5f * fv) + rr * (fl + fv + fl * fv * (rr - 1));
    return {l.weight * (cos_i * value / kPi), cos_i / kPi};
  }
  const float cos_o = dot(s.n, s.wo);
  if (cos_o <= 0) return {};
  const Float3 h = normalize(wi + s.wo);
  const float cos_h = dot(s.n, h);
  if (cos_h <= 0) return {};
  const float d = l.beckmann ? beckmann_d(cos_h, l.alpha2) : ggx_d(cos_h, l.alpha2);
  const float g = smith_g(l, cos_i, cos_o);
  Float3 f = l.weight * (d * g / (4 * cos_o));
  if (l.fresnel == FresnelMode::schlick) f *= schlick(l.f0, dot(wi, h));
  else if (l.fresnel == FresnelMode::principled) f *= principled_fresnel(l, dot(wi, h));
  else if (l.fresnel == FresnelMode::f82) f *= fresnel_f82(l.f0, l.f82_b, dot(wi, h));
  else if (l.fresnel == FresnelMode::dielectric) f = f * fresnel_dielectric(dot(wi, h), l.eta);
  return {f, d * cos_h / (4 * dot(s.wo, h))};
}

float mixture_pdf(const ShadingPoint& s, Float3 wi) {
  float pdf = 0;
  for (int i = 0; i < s.count; ++i)
    if (!s.lobes[i].singular()) pdf += s.lobes[i].pick * evaluate(s, s.lobes[i], wi).pdf;
  return pdf;
}

bool sample(const ShadingPoint& s, Rng& rng, Scatter& out) {
  float u = rng.uniform();
  const float u1 = rng.uniform(), u2 = rng.uniform();
  if (u < s.pick_transparent) {
    out = {LpeEvent::E, nullptr, -s.wo, s.transparency / s.pick_transparent, 0, true};
    return true;
  }
  u -= s.pick_transparent;
  int i = 0;
  while (i < s.count - 1 && u >= s.lobes[i].pick) u -= s.lobes[i++].pick;
  if (s.count == 0 || s.lobes[i].pick <= 0) return false;
  const Lobe& l = s.lobes[i];
  const float cos_o = dot(s.n, s.wo);
  const Float3 mirror = s.n * (2 * cos_o) - s.wo;
  if (l.kind == LobeKind::dielectric) {
    // Glass (Fresnel weighted): reflection with probability F, refraction
    // otherwise, so F cancels; with one part filtered out the other keeps its
    // own share (F or 1 - F). Refraction BSDFs have no Fresnel at all.
    const bool weighted = l.fresnel == FresnelMode::dielectric;
    const float fresnel = weighted ? fresnel_dielectric(cos_o, l.eta) : 0.0f;
    const Float3 scale = l.weight / l.pick;
    const bool both = l.reflect && l.refract;
    if (l.reflect && (!l.refract || u1 < fresnel)) {
      out = {LpeEvent::S, &l, mirror, both ? scale : scale * fresnel, 0, false};
      return true;
    }
    const float sin_t2 = (1 - cos_o * cos_o) / (l.eta * l.eta);
    if (sin_t2 >= 1) return false;  // total internal reflection, which this lobe does not hold
    const float cos_t = std::sqrt(1 - sin_t2);
    // Radiance is not rescaled by eta^2 (as in Cycles): it cancels on closed objects.
    const Float3 wi = normalize(-s.wo / l.eta + s.n * (cos_o / l.eta - cos_t));
    out = {LpeEvent::T, &l, wi, both || !weighted ? scale : scale * (1 - fresnel), 0, true};
    return true;
  }
  if (l.kind == LobeKind::mirror) {
    if (dot(s.ng, mirror) <= 0) return false;
    Float3 w = l.weight / l.pick;
    if (l.fresnel == FresnelMode::schlick) w *= schlick(l.f0, cos_o);
    else if (l.fresnel == FresnelMode::principled) w *= principled_fresnel(l, cos_o);
    else if (l.fresnel == FresnelMode::f82) w *= fresnel_f82(l.f0, l.f82_b, cos_o);
    else if (l.fresnel == FresnelMode::dielectric) w = w * fresnel_dielectric(cos_o, l.eta);
    out = {LpeEvent::S, &l, mirror, w, 0, false};
    return true;
  }
  Float3 wi;
  if (l.kind == LobeKind::lambert || l.kind == LobeKind::oren_nayar || l.kind == LobeKind::principled_diffuse) {
    wi = Frame(s.n).to_world(sample_cosine(u1, u2));
  } else if (l.kind == LobeKind::translucent) {
    wi = Frame(-s.n).to_world(sample_cosine(u1, u2));
  } else if (l.kind == LobeKind::microfacet_transmission) {
    const float tan2 = l.beckmann ? -l.alpha2 * std::log(std::max(1 - u1, 1e-12f)) : l.alpha2 * u1 / (1 - u1);
    const float cos_h = 1 / std::sqrt(1 + tan2), sin_h = std::sqrt(std::fmax(0.0f, 1 - cos_h * cos_h));
    const float phi = 2 * kPi * u2;
    const Float3 h = Frame(s.n).to_world({sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h});
    const float cos_ho = dot(s.wo, h);
    if (cos_ho <= 0) return false;
    const float sin_t2 = (1 - cos_ho * cos_ho) / (l.eta * l.eta);
    if (sin_t2 >= 1) return false;  // total internal reflection: not this lobe's
    const float cos_t = std::sqrt(1 - sin_t2);
    wi = normalize(-s.wo / l.eta + h * (cos_ho / l.eta - cos_t));
  } else {
    const float tan2 = l.beckmann ? -l.alpha2 * std::log(std::max(1 - u1, 1e-12f)) : l.alpha2 * u1 / (1 - u1);
    const float cos_h = 1 / std::sqrt(1 + tan2), sin_h = std::sqrt(std::fmax(0.0f, 1 - cos_h * cos_h));
    const float phi = 2 * kPi * u2;
    const Float3 h = Frame(s.n).to_world({sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h});
    wi = h * (2 * dot(s.wo, h)) - s.wo;
  }
  const LobeValue value = evaluate(s, l, wi);
  if (value.pdf <= 0) return false;
  const float pdf = mixture_pdf(s, wi);
  if (!std::isfinite(pdf) || !finite3(value.f / (l.pick * value.pdf))) return false;
  // One-sample estimator of the sampled lobe; MIS weights use the mixture pdf.
  out = {l.event(), &l, wi, value.f / (l.pick * value.pdf), pdf,
         l.kind == LobeKind::translucent || l.kind == LobeKind::microfacet_transmission};
  return true;
}

}  // namespace tempera::tracer

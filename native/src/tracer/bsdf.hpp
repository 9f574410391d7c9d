#pragma once
// The BSDF at a shading point: a material's closures (scene.hpp) evaluated
// there and expanded into primitive lobes, each labelled with the LPE event
// it scatters into. Cycles' semantics: closure weights multiply (Mix and Add
// Shader), a lobe is picked in proportion to its estimated reflectance, and
// the singular lobes (mirror, smooth glass) are reached by sampling only.
#include <array>

#include "sampling.hpp"
#include "tempera/tracer/lpe.hpp"
#include "tempera/engine/rng.hpp"
#include "tempera/tracer/scene.hpp"

namespace tempera::tracer {

constexpr float kSingularRoughness = 0.01f;  // below: a perfect mirror / smooth glass
constexpr int kMaxLobes = 16;

// lambert: Diffuse BSDF; oren_nayar: Diffuse BSDF with roughness (Cycles' Fujii form);
// principled_diffuse: Principled v1's diffuse with its retro-reflection.
// microfacet_transmission: rough refraction (Walter et al. 2007), no Fresnel inside (Cycles 3.x).
enum class LobeKind {
  lambert, oren_nayar, principled_diffuse, translucent, microfacet, microfacet_transmission, mirror, dielectric
};
// principled: Cycles 3.x's Principled Fresnel, f0 + (1 - f0) (F(cos, eta) - F(1, eta)) / (1 - F(1, eta)).
// f82: Principled v2's metal, Schlick's from f0 less the F82-tint term b cos (1 - cos)^6 (principled_v2.hpp).
enum class FresnelMode { none, schlick, dielectric, principled, f82 };

struct Lobe {
  LobeKind kind = LobeKind::lambert;
  Float3 weight;            // colour times closure weight
  float alpha2 = 0;         // microfacet: alpha^2
  float a = 0, b = 0;       // oren_nayar: A, B; principled_diffuse: a = roughness
  Float3 multiscatter;      // oren_nayar, energy preserving: E_ms (1 - E(viewer)); else 0
  bool beckmann = false;    // microfacet: Beckmann instead of GGX
  bool correlated = false;  // microfacet: height-correlated Smith shadowing (ClosureModel)
  FresnelMode fresnel = FresnelMode::none;  // microfacet_transmission, dielectric: 1 - F(microfacet)
  Float3 f0;                // schlick, principled, f82
  Float3 f82_b;             // f82: the tint term's b
  float eta = 1;            // dielectric: n behind / n in front; microfacet with dielectric Fresnel
  bool reflect = true, refract = true;  // dielectric: which parts exist (refraction-only closures, caustic filter)
  bool sharp = false;       // mirror: a Sharp distribution (never blurred by Filter Glossy)
  // lambert under Principled v2's reflective layers: its weight when reflective caustics are
  // filtered, for Cycles then builds neither those layers nor the layering weight they pass down.
  bool layered = false;
  Float3 unlayered_weight;
  float pick = 0;           // selection probability
  bool singular() const { return kind == LobeKind::mirror || kind == LobeKind::dielectric; }
  bool diffuse() const {
    return kind == LobeKind::lambert || kind == LobeKind::oren_nayar || kind == LobeKind::principled_diffuse ||
           kind == LobeKind::translucent;
  }
  LpeEvent event() const {
    return diffuse() ? LpeEvent::D : kind == LobeKind::microfacet_transmission ? LpeEvent::T : LpeEvent::S;
  }
};

struct ShadingPoint {
  Float3 p, n, ng;  // shading and geometric normals, both on the viewer's side
  Float3 wo;        // towards the previous vertex
  bool front = true;        // the viewer is on the triangle's front side
  std::array<Lobe, kMaxLobes> lobes;
  int count = 0;
  Float3 emission;          // radiance emitted towards wo
  Float3 transparency;      // weight of the straight-through continuation
  float pick_transparent = 0;
};

struct SurfaceInput {  // where and how the material is evaluated
  Float3 p, n, ng, wo;
  bool front;
  float u, v;  // texture coordinates
};

// The material's closures at a surface point.
ShadingPoint shade(const Scene& scene, const Material& material, const SurfaceInput& at);
// Emitted radiance and transparency only (light sampling and shadow rays).
Float3 emission_at(const Scene& scene, const Material& material, const SurfaceInput& at);
Float3 transparency_at(const Scene& scene, const Material& material, const SurfaceInput& at);
// Whether the material has any transparent or emissive closure at all.
bool has_transparency(const Material& material);
Float3 constant_emission(const Material& material);  // for picking emissive triangles

// Drops lobes (after a diffuse bounce, Cycles' caustics options) and renormalises picks.
void filter_caustics(ShadingPoint& s, bool reflective, bool refractive);
// Cycles' Filter Glossy: microfacet lobes (and mirrors that are not Sharp)
// get at least the microfacet alpha `alpha`.
void blur_glossy(ShadingPoint& s, float alpha);

struct LobeValue {
  Float3 f;        // BSDF value times |cos(wi)|
  float pdf = 0;   // direction pdf (solid angle) of the lobe alone
};
LobeValue evaluate(const ShadingPoint& s, const Lobe& lobe, Float3 wi);
// Pdf of BSDF sampling (all non-singular lobes, with their picks) for wi.
float mixture_pdf(const ShadingPoint& s, Float3 wi);

struct Scatter {
  LpeEvent event;
  const Lobe* lobe = nullptr;  // null: transparent
  Float3 wi;
  Float3 weight;     // f cos / pdf
  float pdf = 0;     // mixture pdf for MIS; 0 for singular directions
  bool transmitted = false;  // wi leaves through the surface
};
// Samples one lobe (or the transparent continuation); false: absorbed.
bool sample(const ShadingPoint& s, Rng& rng, Scatter& out);

float fresnel_dielectric(float cos_i, float eta);

// Building blocks of the closures' lobes (bsdf.cpp), shared with principled_v2.cpp.
void add_lobe(ShadingPoint& s, const Lobe& lobe);
// A reflection of `roughness`: a mirror below kSingularRoughness, else microfacet.
Lobe reflection_lobe(Float3 weight, float roughness, bool beckmann, FresnelMode fresnel, Float3 f0);

}  // namespace tempera::tracer

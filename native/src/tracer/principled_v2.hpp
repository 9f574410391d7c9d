#pragma once
// Cycles 4.0's Principled BSDF ("Principled v2") as stacked layers, top down:
// coat, then metal, transmission, a dielectric specular layer and Lambertian
// diffuse. A reflective layer passes down 1 - its directional albedo seen from
// the viewer (Cycles' closure layering weight); metal and transmission take
// their share of what reaches them and pass the rest on. The albedos come from
// numerically computed tables (microfacet_albedo.hpp). Sheen is not traced.
#include "bsdf.hpp"

namespace tempera::tracer {

// Adds the lobes of a Principled v2 closure of `weight` and base colour `base`.
void add_principled_v2(ShadingPoint& s, const Closure& c, Float3 weight, Float3 base, float roughness);

// The F82-tint Fresnel of a metal (Kutz et al., "Novel aspects of the Adobe
// Standard Material"): Schlick's from f0, less b cos (1 - cos)^6, clamped to [0, 1].
Float3 fresnel_f82(Float3 f0, Float3 b, float cos_theta);
// b such that the Fresnel at cos = 1/7 (about 82 degrees) is Schlick's there times `tint`.
Float3 f82_tint_b(Float3 f0, Float3 tint);

}  // namespace tempera::tracer

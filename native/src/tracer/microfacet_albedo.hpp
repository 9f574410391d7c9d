#pragma once
// Directional albedos of a GGX reflection lobe with height-correlated Smith
// shadowing, the quantities Cycles 4's Principled v2 layers its closures by
// (a lower layer gets 1 - the albedo of the layer above) and its Multiscatter
// GGX restores the energy single scattering loses with. Cycles ships them as
// precomputed tables; these are computed here, by quadrature, on first use,
// on the same grids (roughness and view cosine evenly spaced; the IOR axis
// z = sqrt((eta - 1) / (eta + 1)), so z^4 is the normal-incidence Fresnel).
namespace tempera::tracer {

// E(roughness, mu): the albedo of the lobe without Fresnel, seen at cos mu.
float ggx_albedo(float roughness, float mu);
// E_avg(roughness): E averaged over the hemisphere, 2 int E(mu) mu dmu.
float ggx_average_albedo(float roughness);
// s(roughness, mu, eta): the lobe's mean of the Fresnel blend
// (F(eta) - F0(eta)) / (1 - F0(eta)) over its visible microfacet normals, so
// that mix(f0, 1, s) is the albedo of a lobe whose Fresnel goes from f0 to 1
// like a dielectric's of `eta` (> 1), taking the lobe's own albedo as 1.
float ggx_fresnel_blend(float roughness, float mu, float eta);
// The cosine-weighted hemispherical mean of the dielectric Fresnel, 2 int F(mu, eta) mu dmu.
float dielectric_average_fresnel(float eta);

// Kulla and Conty's multiple-scattering compensation, as Cycles' Multiscatter
// GGX applies it on top of the single-scattering lobe: the factor
// 1 + F_ms (1 - E) / E, F_ms = F_ss E_avg / (1 - F_ss (1 - E_avg)), for a lobe
// whose hemispherical mean Fresnel is f_ss (one channel).
float multiscatter_factor(float roughness, float mu, float f_ss);

}  // namespace tempera::tracer

// Cycles 4's Principled v2 in the LPE tracer: white-furnace and energy checks
// of its layers (ClosureModel::principled_v2). Each check fails with its part
// of the model switched off.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "tempera/tracer/embree_tracer.hpp"
#include "test_inputs.hpp"

using namespace tempera;
using tempera::test_inputs::add_sphere;
using tempera::test_inputs::top_camera;

namespace {

constexpr float kPi = 3.14159265358979f;

double mean(const Image& image) {
  double sum = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) sum += image.at(x, y, 0);
  return sum / double(image.pixel_count());
}

Closure principled(Float3 base, float roughness) {
  Closure c;
  c.type = Closure::Type::principled;
  c.color = base;
  c.roughness = roughness;
  c.ior = 1.5f;
  return c;
}

// A sphere of `c` in a white world, seen over its middle (out to sin 0.7, so
// grazing views are included), lit once: one bounce, no inter-reflection.
Scene furnace(const Closure& c, bool v2 = true) {
  Scene s;
  Material m;
  m.closures = {c};
  s.materials = {m};
  add_sphere(s, {0, 0, 0}, 1, 0);
  s.world_radiance = {1, 1, 1};
  s.camera = top_camera(5, 1.4f, 16);
  s.closure_model.height_correlated_shadowing = true;  // as Cycles 4
  s.closure_model.microfacet_glass_fresnel = true;
  s.closure_model.principled_v2 = v2;
  return s;
}

std::vector<double> trace(const Scene& s, const std::vector<std::string>& lpes, int samples = 256) {
  TraceOptions o;
  o.samples = samples;
  o.max_bounces = 1;
  const TraceResult r = trace_lpe(s, lpes, o);
  std::vector<double> out;
  for (const Image& image : r.images) out.push_back(mean(image));
  return out;
}

}  // namespace

TEST(PrincipledV2, MultiscatterMetalIsAWhiteFurnace) {
  // A white metal reflects everything: Multiscatter GGX restores what single
  // scattering loses (1 - E, from the albedo table), so the furnace stays 1;
  // without it a rough metal is visibly darker.
  for (const float roughness : {0.5f, 1.0f}) {
    Closure metal = principled({1, 1, 1}, roughness);
    metal.metallic = 1;
    metal.multiscatter = true;
    const double compensated = trace(furnace(metal), {"L.*E"})[0];
    metal.multiscatter = false;
    const double single = trace(furnace(metal), {"L.*E"})[0];
    EXPECT_NEAR(compensated, 1.0, 0.015) << roughness;
    EXPECT_LT(single, compensated - 0.08) << roughness;
  }
}

TEST(PrincipledV2, DiffuseUnderSpecularGetsOneMinusItsAlbedo) {
  // White dielectric: the Lambertian diffuse below the specular layer is
  // weighted by 1 - the layer's albedo (Fresnel blend table), so specular plus
  // diffuse is a white furnace; a diffuse of full weight would exceed 1.
  Closure white = principled({1, 1, 1}, 0.5f);
  white.multiscatter = true;
  const auto v = trace(furnace(white), {"L.*E", "LSE", "LDE"});
  EXPECT_NEAR(v[0], 1.0, 0.01);
  EXPECT_GT(v[1], 0.03);         // the specular layer reflects ...
  EXPECT_NEAR(v[2], 1 - v[1], 0.01);  // ... what the diffuse below does not
}

TEST(PrincipledV2, DiffuseIsLambertian) {
  // With no specular layer (Specular IOR Level 0: F0 = 0) a grey base is a
  // Lambertian of its colour: 0.5 in a white world. Principled v1's Disney
  // diffuse, with its roughness-driven retro-reflection, is not.
  Closure grey = principled({0.5f, 0.5f, 0.5f}, 1.0f);
  grey.specular_ior_level = 0;
  EXPECT_NEAR(trace(furnace(grey), {"LDE"})[0], 0.5, 0.005);
  grey.specular = 0;  // v1's specular: none either
  EXPECT_GT(std::fabs(trace(furnace(grey, false), {"LDE"})[0] - 0.5), 0.012);
}

TEST(PrincipledV2, CoatIsALayerAndItsTintAbsorbs) {
  // A coat over white diffuse: the coat's reflection plus the diffuse below
  // it stays within the furnace; its tint absorbs along the refracted view ray,
  // tint^(1 / cos_t) with cos_t of the coat IOR: for tint 0.5 and the sphere's
  // middle, about 0.5^1.1, somewhat more than half of the diffuse lost.
  Closure coated = principled({1, 1, 1}, 0.5f);
  coated.specular_ior_level = 0;
  coated.clearcoat = 1;
  coated.clearcoat_roughness = 0.2f;
  const auto clear = trace(furnace(coated), {"L.*E", "LSE", "LDE"});
  EXPECT_GT(clear[1], 0.04);
  EXPECT_NEAR(clear[0], 1.0, 0.01);
  EXPECT_NEAR(clear[2], 1 - clear[1], 0.01);
  coated.coat_tint = {0.5f, 0.5f, 0.5f};
  const auto tinted = trace(furnace(coated), {"LSE", "LDE"});
  EXPECT_NEAR(tinted[0], clear[1], 0.005);  // the coat's own reflection is untinted
  const double ratio = tinted[1] / clear[2];
  EXPECT_GT(ratio, 0.42);
  EXPECT_LT(ratio, 0.49);
}

TEST(PrincipledV2, F82TintDarkensOnlyGrazingMetal) {
  // F82 tint scales the metal's Fresnel near 82 degrees and leaves normal
  // incidence alone: a black tint darkens the sphere's rim, not its centre.
  Closure metal = principled({0.5f, 0.5f, 0.5f}, 0.3f);
  metal.metallic = 1;
  Scene plain = furnace(metal);
  plain.camera = top_camera(5, 2.0f, 32);  // the whole sphere, rim included
  metal.specular_tint = {0, 0, 0};
  Scene tinted = furnace(metal);
  tinted.camera = plain.camera;
  TraceOptions o;
  o.samples = 128;
  o.max_bounces = 1;
  const Image a = trace_lpe(plain, {"LSE"}, o).images[0], b = trace_lpe(tinted, {"LSE"}, o).images[0];
  EXPECT_LT(mean(b), mean(a) * 0.97);
  double centre_a = 0, centre_b = 0;
  for (int y = 14; y < 18; ++y)
    for (int x = 14; x < 18; ++x) centre_a += a.at(x, y, 0), centre_b += b.at(x, y, 0);
  EXPECT_NEAR(centre_b / centre_a, 1.0, 0.02);
}

TEST(PrincipledV2, TransmissionIsGlassWithAnUntintedReflection) {
  // Transmission 1: clear glass in a white world lets through what reaches it
  // (rough: one microfacet closure; smooth: singular). Cycles 4 tints only the
  // refraction, by sqrt(base colour): a red base leaves the reflection white.
  for (const float roughness : {0.0f, 0.3f}) {
    Closure glass = principled({1, 0.25f, 0.25f}, roughness);
    glass.transmission = 1;
    Scene s = furnace(glass);
    TraceOptions o;
    o.samples = 128;
    o.max_bounces = 64;
    const TraceResult r = trace_lpe(s, {"LSE", "L.*TE"}, o);
    double red = 0, green = 0, reflected_red = 0, reflected_green = 0;
    const Image &t = r.images[1], &reflected = r.images[0];
    for (int y = 0; y < t.height(); ++y)
      for (int x = 0; x < t.width(); ++x) {
        red += t.at(x, y, 0), green += t.at(x, y, 1);
        reflected_red += reflected.at(x, y, 0), reflected_green += reflected.at(x, y, 1);
      }
    EXPECT_GT(reflected_red, 0) << roughness;
    EXPECT_NEAR(reflected_green / reflected_red, 1.0, 0.02) << roughness;  // white reflection
    EXPECT_LT(green / red, 0.6) << roughness;  // red refraction: sqrt(0.25) = 0.5 a pass
    glass.color = {1, 1, 1};
    const double clear = mean(trace_lpe(furnace(glass), {"L.*E"}, o).images[0]);
    EXPECT_GT(clear, 0.85) << roughness;  // white glass: at most what reaches it, little lost
    EXPECT_LT(clear, 1.02) << roughness;
  }
}

TEST(PrincipledV2, SameResultForAnyThreadCount) {
  // The albedo tables are built once, whichever thread asks first; every layer is deterministic.
  Closure c = principled({0.7f, 0.3f, 0.2f}, 0.4f);
  c.metallic = 0.3f;
  c.transmission = 0.2f;
  c.clearcoat = 0.6f;
  c.coat_tint = {0.8f, 0.9f, 1.0f};
  c.specular_tint = {1.0f, 0.8f, 0.8f};
  c.multiscatter = true;
  const Scene s = furnace(c);
  TraceOptions one, two;
  one.samples = two.samples = 8;
  one.max_bounces = two.max_bounces = 8;
  one.seed = two.seed = 5;
  one.threads = 1;
  two.threads = 2;
  const TraceResult a = trace_lpe(s, {"L.*E", "LSE", "LDE"}, one), b = trace_lpe(s, {"L.*E", "LSE", "LDE"}, two);
  for (std::size_t k = 0; k < a.images.size(); ++k) {
    EXPECT_EQ(std::memcmp(a.images[k].data(), b.images[k].data(), a.images[k].pixel_count() * 3 * sizeof(float)), 0)
        << k;
    EXPECT_GT(mean(a.images[k]), 0.0) << k;
  }
}

TEST(PrincipledV2, WithoutReflectiveCausticsTheDiffuseHasNoLayersAbove) {
  // After a diffuse bounce with reflective caustics off, Cycles builds none of
  // Principled v2's reflective layers, nor the 1 - albedo they pass down: the
  // diffuse then has its full weight. Seen through a Lambert floor (LDDE: the
  // floor, then a white dielectric sphere above it), the sphere's diffuse is
  // 1 / (1 - its specular albedo) brighter than with caustics on.
  Scene s;
  Material floor;
  Closure lambert;
  lambert.type = Closure::Type::diffuse;
  lambert.color = {0.8f, 0.8f, 0.8f};
  floor.closures = {lambert};
  Material sphere;
  Closure white = principled({1, 1, 1}, 0.5f);
  white.multiscatter = true;
  sphere.closures = {white};
  s.materials = {floor, sphere};
  const float h = 50;
  const auto base = std::uint32_t(s.vertices.size());
  s.vertices.insert(s.vertices.end(), {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}});
  s.triangles.push_back({base, base + 1, base + 2});
  s.triangles.push_back({base, base + 2, base + 3});
  s.triangle_materials.insert(s.triangle_materials.end(), {0, 0});
  add_sphere(s, {0, 0, 1.2f}, 1, 1);
  s.world_radiance = {1, 1, 1};
  s.camera = top_camera(5, 6, 24);
  s.closure_model.height_correlated_shadowing = true;
  s.closure_model.principled_v2 = true;
  TraceOptions o;
  o.samples = 512;
  o.max_bounces = 2;
  const double with_caustics = mean(trace_lpe(s, {"LDDE"}, o).images[0]);
  o.caustics_reflective = false;
  const double without = mean(trace_lpe(s, {"LDDE"}, o).images[0]);
  EXPECT_GT(without, with_caustics * 1.03);
  EXPECT_LT(without, with_caustics * 1.10);
}

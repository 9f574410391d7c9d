// Analytic checks of the LPE tracer: each scene has a closed-form radiance.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <utility>

#include "tempera/tracer/embree_tracer.hpp"
#include "tempera/engine/error.hpp"
#include "test_inputs.hpp"

using namespace tempera;
using tempera::test_inputs::add_sphere;
using tempera::test_inputs::top_camera;

namespace {

constexpr float kPi = 3.14159265358979f;

void add_quad(Scene& s, Float3 a, Float3 b, Float3 c, Float3 d, int material) {
  const auto base = std::uint32_t(s.vertices.size());
  s.vertices.insert(s.vertices.end(), {a, b, c, d});
  s.triangles.push_back({base, base + 1, base + 2});
  s.triangles.push_back({base, base + 2, base + 3});
  s.triangle_materials.insert(s.triangle_materials.end(), {material, material});
}

// A floor at z = 0 (counter-clockwise seen from above) of half size `half`.
void add_floor(Scene& s, float half, int material) {
  add_quad(s, {-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}, material);
}

Material lambert(float albedo) {  // a Diffuse BSDF
  Closure c;
  c.type = Closure::Type::diffuse;
  c.color = {albedo, albedo, albedo};
  Material m;
  m.closures = {c};
  return m;
}

double mean(const Image& image, int channel = 0) {
  double sum = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) sum += image.at(x, y, channel);
  return sum / double(image.pixel_count());
}

TraceOptions options(int samples) {
  TraceOptions o;
  o.samples = samples;
  return o;
}

Scene sun_scene(float cos_sun) {
  Scene s;
  s.materials = {lambert(0.6f)};
  add_floor(s, 100, 0);
  Light sun;
  sun.type = Light::Type::sun;
  sun.direction = {std::sqrt(1 - cos_sun * cos_sun), 0, cos_sun};
  sun.irradiance = {2, 3, 4};
  s.lights = {sun};
  s.camera = top_camera(5, 2, 16);
  return s;
}

}  // namespace

TEST(Tracer, SunOnLambertPlane) {
  const float cos_sun = 0.8f;
  const TraceResult r = trace_lpe(sun_scene(cos_sun), {"LDE", "LSE", "L.*E"}, options(64));
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(mean(r.images[0], c), 0.6 / kPi * (2 + c) * cos_sun, 0.02 * 0.6 / kPi * (2 + c) * cos_sun);
  EXPECT_EQ(mean(r.images[1]), 0.0);  // no glossy lobe at all
  EXPECT_NEAR(mean(r.images[2]), mean(r.images[0]), 1e-6);
}

TEST(Tracer, PointLightFollowsInverseSquareLaw) {
  Scene s;
  s.materials = {lambert(0.5f)};
  add_floor(s, 100, 0);
  Light point;
  point.type = Light::Type::point;
  point.position = {0, 0, 1};
  point.intensity = {10, 10, 10};
  s.lights = {point};
  s.camera = top_camera(5, 4, 16);
  const TraceResult r = trace_lpe(s, {"LDE"}, options(64));
  for (int py = 0; py < 16; py += 3)
    for (int px = 0; px < 16; px += 3) {
      double expected = 0;  // the analytic radiance averaged over the pixel
      for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j) {
          const double x = (px + (i + 0.5) / 8) / 16 * 4 - 2, y = 2 - (py + (j + 0.5) / 8) / 16 * 4;
          expected += 0.5 / kPi * 10 / std::pow(x * x + y * y + 1, 1.5) / 64;
        }
      EXPECT_NEAR(r.images[0].at(px, py, 0), expected, 0.02 * expected) << px << "," << py;
    }
}

TEST(Tracer, FurnaceWorldOnWhitePlane) {
  Scene s;
  s.materials = {lambert(1.0f)};
  add_floor(s, 1000, 0);
  s.world_radiance = {0.7f, 0.7f, 0.7f};
  s.camera = top_camera(5, 2, 8);
  const TraceResult r = trace_lpe(s, {"LDE", "LE", "L.*E"}, options(64));
  EXPECT_NEAR(mean(r.images[0]), 0.7, 0.02 * 0.7);
  EXPECT_EQ(mean(r.images[1]), 0.0);  // the camera sees only the plane
}

TEST(Tracer, DiskAreaLightMatchesClosedForm) {
  // Irradiance under the centre of a disk of radius R at height h: pi L R^2 / (h^2 + R^2).
  Scene s;
  s.materials = {lambert(0.5f)};
  add_floor(s, 100, 0);
  Light disk;
  disk.type = Light::Type::area;
  disk.shape = Light::Shape::disk;
  disk.center = {0, 0, 1};
  disk.axis_u = {1, 0, 0};
  disk.axis_v = {0, 1, 0};
  disk.normal = {0, 0, -1};
  disk.size_u = disk.size_v = 1.2f;
  disk.radiance = {3, 3, 3};
  s.lights = {disk};
  s.camera = top_camera(5, 0.01f, 8);  // looks through the light's back (it emits downwards only)
  const TraceResult r = trace_lpe(s, {"LDE"}, options(256));
  const double expected = 0.5 / kPi * kPi * 3 * 0.36 / (1 + 0.36);
  EXPECT_NEAR(mean(r.images[0]), expected, 0.02 * expected);
}

TEST(Tracer, EmissiveQuadLightsLikeAnAreaLight) {
  // Camera between the light (z = 1) and the floor, so it only sees the floor.
  Scene emissive;
  Material glow;  // the Principled-like format: black, emitting
  glow.base_color = {0, 0, 0};
  glow.emission = {2, 2, 2};
  emissive.materials = {lambert(0.5f), glow};
  add_floor(emissive, 100, 0);
  add_quad(emissive, {-0.5f, -0.5f, 1}, {-0.5f, 0.5f, 1}, {0.5f, 0.5f, 1}, {0.5f, -0.5f, 1}, 1);
  emissive.camera = top_camera(0.5f, 2, 8);
  Scene area = emissive;
  area.vertices.resize(4);
  area.triangles.resize(2);
  area.triangle_materials.resize(2);
  Light rect;
  rect.type = Light::Type::area;
  rect.center = {0, 0, 1};
  rect.axis_u = {1, 0, 0};
  rect.axis_v = {0, 1, 0};
  rect.normal = {0, 0, -1};
  rect.radiance = {2, 2, 2};
  area.lights = {rect};
  const TraceResult a = trace_lpe(emissive, {"LDE"}, options(128));
  const TraceResult b = trace_lpe(area, {"LDE"}, options(128));
  EXPECT_GT(mean(a.images[0]), 0.1);
  EXPECT_NEAR(mean(a.images[0]), mean(b.images[0]), 0.02 * mean(b.images[0]));
}

TEST(Tracer, CausticsNeedAMirror) {
  Scene s;
  s.materials = {lambert(0.8f)};
  add_floor(s, 20, 0);
  Light lamp;
  lamp.type = Light::Type::area;
  lamp.center = {1, 0, 4};
  lamp.axis_u = {1, 0, 0};
  lamp.axis_v = {0, 1, 0};
  lamp.normal = {0, 0, -1};
  lamp.size_u = lamp.size_v = 0.5f;
  lamp.radiance = {40, 40, 40};
  s.lights = {lamp};
  s.camera = top_camera(6, 6, 24);
  const std::vector<std::string> caustics = {"LS+DE", "LDE"};
  const TraceResult without = trace_lpe(s, caustics, options(16));
  EXPECT_EQ(mean(without.images[0]), 0.0);
  EXPECT_GT(mean(without.images[1]), 0.0);

  Material mirror;
  mirror.base_color = {0.9f, 0.9f, 0.9f};
  mirror.metallic = 1;
  mirror.roughness = 0;
  s.materials.push_back(mirror);
  add_sphere(s, {0, 0, 1.5f}, 0.5f, 1);
  const TraceResult with = trace_lpe(s, caustics, options(128));  // caustic paths are rare
  EXPECT_GT(mean(with.images[0]), 0.0);
}

TEST(Tracer, NeverMatchingExpressionIsExactlyZero) {
  const TraceResult r = trace_lpe(sun_scene(1), {"L[^LDST]E", "LTE", "LDE"}, options(4));
  EXPECT_EQ(mean(r.images[0]), 0.0);
  EXPECT_EQ(mean(r.images[1]), 0.0);
  EXPECT_GT(mean(r.images[2]), 0.0);
}

TEST(Tracer, SameResultForAnyThreadCount) {
  Scene s = sun_scene(0.9f);
  s.world_radiance = {0.2f, 0.2f, 0.2f};
  s.materials.push_back(lambert(0.5f));
  s.materials[1].roughness = 0.3f;
  s.materials[1].specular = 0.5f;
  add_sphere(s, {0, 0, 0.5f}, 0.5f, 1, 12, 24);
  TraceOptions one = options(8), two = options(8);
  one.seed = two.seed = 7;
  one.threads = 1;
  two.threads = 2;
  const TraceResult a = trace_lpe(s, {"L.*E", "L.*DDE"}, one);
  const TraceResult b = trace_lpe(s, {"L.*E", "L.*DDE"}, two);
  for (int k = 0; k < 2; ++k)
    EXPECT_EQ(std::memcmp(a.images[k].data(), b.images[k].data(), a.images[k].pixel_count() * 3 * sizeof(float)), 0);
  EXPECT_GT(mean(a.images[1]), 0.0);
}

TEST(Tracer, AlphaCoversTheGeometry) {
  Scene s;
  s.materials = {lambert(0.5f)};
  add_quad(s, {-3, -3, 0}, {0, -3, 0}, {0, 3, 0}, {-3, 3, 0}, 0);  // the left half of the view
  s.camera = top_camera(5, 4, 16);
  const TraceResult r = trace_lpe(s, {"LDE"}, options(16));
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) EXPECT_FLOAT_EQ(r.alpha.at(x, y, 0), x < 8 ? 1.0f : 0.0f) << x << "," << y;
}

TEST(Tracer, PerspectiveCameraCentreAndShift) {
  // A perspective camera looking down at a floor whose left half is black:
  // shifting the view by half the width moves the boundary off the image.
  Scene s;
  s.materials = {lambert(0.5f), lambert(0.0f)};
  add_quad(s, {-50, -50, 0}, {0, -50, 0}, {0, 50, 0}, {-50, 50, 0}, 1);
  add_quad(s, {0, -50, 0}, {50, -50, 0}, {50, 50, 0}, {0, 50, 0}, 0);
  s.world_radiance = {1, 1, 1};
  Camera& c = s.camera;
  c.camera_to_world = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 2, 0, 0, 0, 1};
  c.width = 20;
  c.height = 10;
  c.tan_half_fov_x = 0.5f;
  c.tan_half_fov_y = 0.25f;
  const TraceResult centred = trace_lpe(s, {"LDE"}, options(4));
  EXPECT_EQ(centred.images[0].at(9, 5, 0), 0.0f);
  EXPECT_GT(centred.images[0].at(10, 5, 0), 0.0f);
  c.shift_x = 0.5f;  // half the (larger) image width: the view now spans x in [0, 2] on the floor
  const TraceResult shifted = trace_lpe(s, {"LDE"}, options(4));
  EXPECT_GT(shifted.images[0].at(0, 5, 0), 0.0f);
}

TEST(Tracer, RejectsBadInput) {
  Scene s = sun_scene(1);
  EXPECT_THROW(trace_lpe(s, {"L(DE"}, options(1)), ValueError);
  s.vertices[2].y = NAN;
  EXPECT_THROW(trace_lpe(s, {"LDE"}, options(1)), ValueError);
  s = sun_scene(1);
  s.triangles[1][2] = 9;
  EXPECT_THROW(trace_lpe(s, {"LDE"}, options(1)), ValueError);
  s = sun_scene(1);
  s.camera.width = 0;
  EXPECT_THROW(trace_lpe(s, {"LDE"}, options(1)), ValueError);
  s = sun_scene(1);
  s.lights[0].max_bounces = -1;
  EXPECT_THROW(trace_lpe(s, {"LDE"}, options(1)), ValueError);
}

TEST(Tracer, ProgressCanCancel) {
  int calls = 0;
  EXPECT_THROW(trace_lpe(sun_scene(1), {"LDE"}, options(1), [&](double) { return ++calls < 2; }), CancelledError);
}

TEST(Tracer, TextureIsBilinearWithRepeatAndBottomLeftOrigin) {
  Material m;
  m.base_color_texture = Image(2, 2, 3);
  m.base_color_texture.at(0, 0, 0) = 1;  // top-left texel: red
  m.base_color_texture.at(1, 1, 2) = 1;  // bottom-right texel: blue
  EXPECT_FLOAT_EQ(base_color_at(m, 0.25f, 0.75f).x, 1);  // texel centres
  EXPECT_FLOAT_EQ(base_color_at(m, 0.75f, 0.25f).z, 1);
  EXPECT_FLOAT_EQ(base_color_at(m, 1.75f, -0.75f).z, 1);  // repeat
  EXPECT_FLOAT_EQ(base_color_at(m, 0.5f, 0.75f).x, 0.5f);  // halfway between texel centres
  EXPECT_FLOAT_EQ(base_color_at(m, 0.0f, 0.75f).x, 0.5f);  // blends with the wrapped column
}

TEST(Tracer, SpotLightIsAPointLightInsideItsCone) {
  Scene s;
  s.materials = {lambert(0.5f)};
  add_floor(s, 100, 0);
  Light spot;
  spot.type = Light::Type::spot;
  spot.position = {0, 0, 1};
  spot.direction = {0, 0, -1};
  spot.intensity = {10, 10, 10};
  spot.spot_half_angle = 0.5f;  // reaches tan(0.5) = 0.546 m on the floor
  s.lights = {spot};
  s.camera = top_camera(5, 4, 16);  // pixels 0.25 m wide
  const TraceResult r = trace_lpe(s, {"LDE"}, options(16));
  EXPECT_EQ(r.images[0].at(0, 0, 0), 0.0f);  // outside the cone
  // The pixel at (0.125, 0.125) m is well inside; compare with the point light
  // law times Cycles' cosine to the spot's axis (1 / sqrt(d2) here).
  const double d2 = 2 * 0.125 * 0.125 + 1;
  EXPECT_NEAR(r.images[0].at(8, 7, 0), 0.5 / kPi * 10 / std::pow(d2, 2.0), 0.03);
}

TEST(Tracer, SpotLightAxisCosineIsCycles3Only) {
  // Cycles 4.0 dropped the cosine to the spot's axis: off the axis the spot
  // is then the plain point light law, with it 3.x's cosine darker.
  for (const bool axis_cosine : {true, false}) {
    Scene s;
    s.materials = {lambert(0.5f)};
    add_floor(s, 100, 0);
    Light spot;
    spot.type = Light::Type::spot;
    spot.position = {0, 0, 1};
    spot.direction = {0, 0, -1};
    spot.intensity = {10, 10, 10};
    spot.spot_half_angle = 0.6f;
    spot.spot_axis_cosine = axis_cosine;
    s.lights = {spot};
    s.camera = top_camera(5, 4, 16);
    const TraceResult r = trace_lpe(s, {"LDE"}, options(16));
    const double d2 = 0.375 * 0.375 + 0.125 * 0.125 + 1, cosine = 1 / std::sqrt(d2);  // pixel (0.375, 0.125) m
    const double expected = 0.5 / kPi * 10 / (d2 * std::sqrt(d2)) * (axis_cosine ? cosine : 1.0);
    EXPECT_NEAR(r.images[0].at(8, 9, 0), expected, 0.02 * expected) << axis_cosine;
  }
}

// ------------------------------------------------------------------ Cycles closures

namespace {

Closure closure(Closure::Type type, Float3 color, float roughness = 0) {
  Closure c;
  c.type = type;
  c.color = color;
  c.roughness = roughness;
  return c;
}

Material of(std::vector<Closure> closures) {
  Material m;
  m.closures = std::move(closures);
  return m;
}

Factor constant(float value, bool invert) {
  Factor f;
  f.value = value;
  f.invert = invert;
  return f;
}

}  // namespace

TEST(Tracer, MixShaderWeightsItsClosures) {
  Scene s = sun_scene(1);
  Closure a = closure(Closure::Type::diffuse, {0.8f, 0.8f, 0.8f}), b = closure(Closure::Type::diffuse, {0.2f, 0.4f, 0.6f});
  a.factors = {constant(0.3f, true)};  // the first shader: 1 - fac
  b.factors = {constant(0.3f, false)};
  s.materials = {of({a, b})};
  const TraceResult r = trace_lpe(s, {"LDE", "LSE"}, options(64));
  for (int c = 0; c < 3; ++c) {
    const double albedo = 0.7 * 0.8 + 0.3 * (0.2 + 0.2 * c);
    EXPECT_NEAR(mean(r.images[0], c), albedo / kPi * (2 + c), 0.02 * albedo / kPi * (2 + c));
  }
  EXPECT_EQ(mean(r.images[1]), 0.0);  // Diffuse BSDFs have no glossy lobe
}

TEST(Tracer, GlossyClosureIsOnlyS) {
  Scene s = sun_scene(0.9f);
  s.materials = {of({closure(Closure::Type::glossy, {1, 1, 1}, 0.6f)})};
  const TraceResult r = trace_lpe(s, {"LDE", "LSE"}, options(16));
  EXPECT_EQ(mean(r.images[0]), 0.0);
  EXPECT_GT(mean(r.images[1]), 0.01);
}

TEST(Tracer, FresnelFactorAtNormalIncidence) {
  // Seen and lit from straight above, a Fresnel(1.5) mix keeps 1 - 0.04 of the diffuse.
  Scene s = sun_scene(1);
  Closure d = closure(Closure::Type::diffuse, {0.5f, 0.5f, 0.5f});
  Factor f;
  f.kind = Factor::Kind::fresnel;
  f.value = 1.5f;
  f.invert = true;
  d.factors = {f};
  s.materials = {of({d})};
  const TraceResult r = trace_lpe(s, {"LDE"}, options(16));
  const double expected = 0.96 * 0.5 / kPi * 2;
  EXPECT_NEAR(mean(r.images[0], 0), expected, 0.01 * expected);
}

TEST(Tracer, TransparentSurfaceIsPassedWithoutAnEvent) {
  // A half-transparent black sheet between the camera, the sun and the floor:
  // the floor is seen through it (x 0.5) and lit through it (x 0.5), and the
  // path is still LDE.
  Scene s = sun_scene(1);
  s.materials.push_back(of({closure(Closure::Type::transparent, {0.5f, 0.5f, 0.5f})}));
  add_quad(s, {-100, -100, 1}, {100, -100, 1}, {100, 100, 1}, {-100, 100, 1}, 1);
  const TraceResult r = trace_lpe(s, {"LDE", "L.*E"}, options(32));
  const double expected = 0.25 * 0.6 / kPi * 2;
  EXPECT_NEAR(mean(r.images[0], 0), expected, 0.02 * expected);
  EXPECT_NEAR(mean(r.images[1], 0), expected, 0.02 * expected);
}

TEST(Tracer, TranslucentLightsThroughTheSurfaceAsD) {
  Scene s = sun_scene(1);
  s.lights[0].direction = {0, 0, -1};  // the sun is below the sheet
  s.materials = {of({closure(Closure::Type::translucent, {0.6f, 0.6f, 0.6f})})};
  const TraceResult r = trace_lpe(s, {"LDE"}, options(32));
  EXPECT_NEAR(mean(r.images[0], 0), 0.6 / kPi * 2, 0.02 * 0.6 / kPi * 2);
}

TEST(Tracer, EnvironmentMapIsImportanceSampledAndUpIsTheTopRow) {
  // A map bright above the horizon only: a white plane facing up sees pi x 1.
  Scene s;
  s.materials = {lambert(1.0f)};
  add_floor(s, 1000, 0);
  Image map(64, 32, 4);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) map.at(x, y, c) = 1;
  s.textures = {map};
  s.world_map = 0;
  s.world_radiance = {1, 1, 1};
  s.camera = top_camera(5, 2, 8);
  const TraceResult r = trace_lpe(s, {"LDE"}, options(64));
  EXPECT_NEAR(mean(r.images[0]), 1.0, 0.02);
}

TEST(Tracer, BounceLimitsAndCausticsOptionsRemovePaths) {
  // A diffuse floor and a glossy wall (facing -y) under a sun that lights both.
  Scene s = sun_scene(0.7f);
  s.lights[0].direction = normalize(Float3{0.3f, -0.65f, 0.7f});
  s.materials.push_back(of({closure(Closure::Type::glossy, {0.9f, 0.9f, 0.9f}, 0.3f)}));
  add_quad(s, {-2, 1, 0}, {2, 1, 0}, {2, 1, 3}, {-2, 1, 3}, 1);
  s.camera = top_camera(5, 4, 16);
  TraceOptions o = options(16);
  const TraceResult all = trace_lpe(s, {"L.*DDE", "LS+DE", "LDE"}, o);
  EXPECT_GT(mean(all.images[1]), 0.0);
  o.diffuse_bounces = 0;
  o.caustics_reflective = false;
  const TraceResult cut = trace_lpe(s, {"L.*DDE", "LS+DE", "LDE"}, o);
  EXPECT_EQ(mean(cut.images[0]), 0.0);  // no second diffuse bounce
  EXPECT_EQ(mean(cut.images[1]), 0.0);  // no glossy lobe after a diffuse bounce
  EXPECT_NEAR(mean(cut.images[2]), mean(all.images[2]), 1e-6);  // direct light untouched
}

TEST(Tracer, RayVisibilityHidesFromCameraButNotFromShadows) {
  Scene s = sun_scene(1);
  s.materials.push_back(lambert(0.5f));
  add_quad(s, {-100, -100, 1}, {100, -100, 1}, {100, 100, 1}, {-100, 100, 1}, 1);
  s.triangle_visibility = {kVisibleAll, kVisibleAll, kVisibleAll & ~kVisibleCamera, kVisibleAll & ~kVisibleCamera};
  const TraceResult r = trace_lpe(s, {"LDE"}, options(4));
  EXPECT_EQ(mean(r.alpha), 1.0);       // the camera sees the floor
  EXPECT_EQ(mean(r.images[0]), 0.0);  // which the hidden sheet still shadows
}

TEST(Tracer, SoftPointLightAsDiskOrSphere) {
  // Far from the light both shapes give the point light's law; the sphere is
  // also reached by BSDF rays (MIS), the disk facing the shaded point too.
  for (const auto shape : {Light::SoftShape::disk, Light::SoftShape::sphere}) {
    Scene s;
    s.materials = {lambert(0.5f)};
    add_floor(s, 100, 0);
    Light point;
    point.type = Light::Type::point;
    point.position = {0, 0, 3};
    point.radius = 0.3f;
    point.soft_shape = shape;
    point.intensity = {10, 10, 10};
    s.lights = {point};
    s.camera = top_camera(2.5f, 0.2f, 4);
    const TraceResult r = trace_lpe(s, {"LDE"}, options(256));
    const double expected = 0.5 / kPi * 10 / 9;
    EXPECT_NEAR(mean(r.images[0]), expected, 0.03 * expected) << int(shape);
  }
}

namespace {

// A white-ish diffuse floor and wall under a large soft point light: much of
// the light the camera sees has bounced off the other surface.
Scene corner_under_soft_light(float radius) {
  Scene s;
  s.materials = {lambert(0.8f)};
  add_floor(s, 4, 0);
  add_quad(s, {-4, 1, 0}, {4, 1, 0}, {4, 1, 6}, {-4, 1, 6}, 0);
  Light point;
  point.type = Light::Type::point;
  point.position = {0, -1, 3};
  point.radius = radius;
  point.intensity = {40, 40, 40};
  s.lights = {point};
  s.camera = top_camera(5, 3, 12);
  return s;
}

// Mean LDE of a corner under a soft light of `radius`, with MIS and with light
// sampling alone (the light's Multiple Importance off): both are unbiased.
std::pair<double, double> lde_with_and_without_mis(float radius) {
  Scene s = corner_under_soft_light(radius);
  const double mis = mean(trace_lpe(s, {"LDE"}, options(256)).images[0]);
  s.lights[0].multiple_importance = false;
  return {mis, mean(trace_lpe(s, {"LDE"}, options(256)).images[0])};
}

}  // namespace

TEST(Tracer, LightMaxBouncesLimitsItsNextEventEstimation) {
  // Cycles' Light > Max Bounces: the light is sampled only at vertices after
  // at most that many bounces; BSDF rays still reach it, weighted by MIS.
  Scene s = corner_under_soft_light(0.5f);
  const std::vector<std::string> lpes = {"LDE", "LD{2}E", "LD{3,}E"};
  const TraceResult all = trace_lpe(s, lpes, options(64));
  s.lights[0].max_bounces = 1;
  const TraceResult one = trace_lpe(s, lpes, options(64));
  s.lights[0].max_bounces = 0;
  const TraceResult none = trace_lpe(s, lpes, options(64));
  // The random numbers of a skipped light are drawn all the same, so the
  // paths the limit allows are the same paths, bit for bit.
  EXPECT_EQ(mean(one.images[0]), mean(all.images[0]));
  EXPECT_EQ(mean(one.images[1]), mean(all.images[1]));
  EXPECT_EQ(mean(none.images[0]), mean(all.images[0]));
  ASSERT_GT(mean(all.images[2]), 0.0);
  // Beyond the limit only the BSDF-sampled hits of the disk remain, weighted
  // by MIS against a sampling that no longer happens: most light is gone.
  EXPECT_LT(mean(one.images[2]), 0.3 * mean(all.images[2]));
  EXPECT_GT(mean(one.images[2]), 0.0);
  EXPECT_LT(mean(none.images[1]), 0.3 * mean(all.images[1]));
  EXPECT_GT(mean(none.images[1]), 0.0);
}

TEST(Tracer, SoftLightReachingTheSurfaceKeepsItsEnergy) {
  // A disk light whose radius is larger than its height above the floor (a
  // large light near a backdrop): BSDF rays from floor points closer to the
  // light than its radius still hit the disk facing them, as in Cycles, so
  // MIS and light sampling alone agree in the mean.
  const auto [mis, light_only] = lde_with_and_without_mis(4.0f);
  EXPECT_NEAR(mis, light_only, 0.02 * light_only);
}

TEST(Tracer, LightWithoutMultipleImportanceIsOnlyFoundBySampling) {
  // With Multiple Importance off BSDF rays pass through the light and its
  // samples take full weight: the same light in the mean. The light is large,
  // so that BSDF rays carry about a sixth of it under MIS: skipping them
  // while the samples kept their MIS weights would fail.
  const auto [mis, light_only] = lde_with_and_without_mis(2.5f);
  EXPECT_NEAR(light_only, mis, 0.02 * mis);

  // Only BSDF rays find a light in a mirror: without Multiple Importance the
  // mirror shows none, as in Cycles.
  Scene mirror = corner_under_soft_light(1.0f);
  mirror.materials = {of({closure(Closure::Type::glossy, {1, 1, 1}, 0)})};
  mirror.materials[0].closures[0].distribution = Closure::Distribution::sharp;
  mirror.lights[0].position = {0, 0, 3};
  EXPECT_GT(mean(trace_lpe(mirror, {"LSE"}, options(16)).images[0]), 0.0);
  mirror.lights[0].multiple_importance = false;
  EXPECT_EQ(mean(trace_lpe(mirror, {"LSE"}, options(16)).images[0]), 0.0);
}

TEST(Tracer, DiffuseRoughnessIsOrenNayar) {
  // Lit and seen from straight above, Cycles' Oren-Nayar (Fujii) gives
  // albedo x E / (pi + (3 pi - 4) / 6 sigma): darker than Lambert.
  Scene s = sun_scene(1);
  s.materials = {of({closure(Closure::Type::diffuse, {0.6f, 0.6f, 0.6f}, 0.8f)})};
  const TraceResult r = trace_lpe(s, {"LDE"}, options(16));
  const double expected = 0.6 * 2 / (kPi + (3 * kPi - 4) / 6 * 0.8);
  EXPECT_NEAR(mean(r.images[0], 0), expected, 0.01 * expected);
}

TEST(Tracer, EnergyPreservingOrenNayarKeepsAWhiteFurnaceWhite) {
  // Cycles 4.3's Oren-Nayar adds back, by OpenPBR's multiple-scattering term,
  // what Fujii's single scattering loses: a white rough plane under a white
  // world returns all of it, 3.x's form only E(straight up) = pi a = 0.78.
  // A grey one returns less than Lambert of its colour and more than 3.x's.
  for (const float albedo : {1.0f, 0.5f}) {
    Scene s;
    s.materials = {of({closure(Closure::Type::diffuse, {albedo, albedo, albedo}, 1.0f)})};
    add_floor(s, 1000, 0);
    s.world_radiance = {1, 1, 1};
    s.camera = top_camera(5, 2, 8);
    const double fujii = mean(trace_lpe(s, {"LDE"}, options(256)).images[0]);
    s.closure_model.energy_preserving_oren_nayar = true;
    const double preserving = mean(trace_lpe(s, {"LDE"}, options(256)).images[0]);
    const double single = albedo * kPi / (kPi + (kPi / 2 - 2.0 / 3));
    EXPECT_NEAR(fujii, single, 0.02 * single) << albedo;
    if (albedo == 1.0f) {
      EXPECT_NEAR(preserving, 1.0, 0.02);
    } else {  // + c^3 E_avg (1 - E) / (1 - c (1 - E_avg)), E_avg = 0.833
      EXPECT_NEAR(preserving, single + 0.0253, 0.02 * single);
      EXPECT_LT(preserving, albedo);
    }
  }
}

TEST(Tracer, RoughGlassSphereInAFurnaceLosesLittleEnergy) {
  // Clear glass in a white world: what comes out is at most what went in,
  // and a single-scattering microfacet model loses only a little at roughness 0.3.
  // Nearly smooth glass (roughness 0.02) must stay finite: its GGX peak is sharp.
  for (const float roughness : {0.02f, 0.3f}) {
    Scene s;
    Closure glass = closure(Closure::Type::glass, {1, 1, 1}, roughness);
    glass.ior = 1.5f;
    s.materials = {of({glass})};
    add_sphere(s, {0, 0, 0}, 1, 0);
    s.world_radiance = {1, 1, 1};
    s.camera = top_camera(5, 0.8f, 8);  // sees only the sphere's middle
    TraceOptions o = options(64);
    o.max_bounces = 64;
    const TraceResult r = trace_lpe(s, {"L.*E", "L.*TE"}, o);
    EXPECT_GT(mean(r.images[0]), 0.85) << roughness;
    EXPECT_LT(mean(r.images[0]), 1.02) << roughness;
    EXPECT_GT(mean(r.images[1]), 0.5) << roughness;  // most of it came through the glass
  }
}

// A white rough sphere in a white world seen whole: what it reflects once (LSE).
double furnace_glossy(float roughness, bool correlated, bool beckmann) {
  Scene s;
  Closure g = closure(Closure::Type::glossy, {1, 1, 1}, roughness);
  if (beckmann) g.distribution = Closure::Distribution::beckmann;
  s.materials = {of({g})};
  add_sphere(s, {0, 0, 0}, 1, 0);
  s.world_radiance = {1, 1, 1};
  s.camera = top_camera(5, 1.4f, 16);  // the sphere out to sin = 0.7: grazing views included
  s.closure_model.height_correlated_shadowing = correlated;
  TraceOptions o = options(256);
  o.max_bounces = 1;
  return mean(trace_lpe(s, {"LSE"}, o).images[0]);
}

TEST(Tracer, HeightCorrelatedShadowingLosesLessEnergy) {
  // Cycles 4.0's Smith shadowing 1 / (1 + Lambda(i) + Lambda(o)) is never below
  // 3.x's G1(i) G1(o) (they differ by Lambda(i) Lambda(o), second order in
  // alpha): at roughness 0.9 GGX's single-scattering albedo rises by about 2 %
  // (Beckmann's Lambda is 0 beyond a = 1.6, so it gains less), yet stays at most 1.
  for (const bool beckmann : {false, true}) {
    const double separable = furnace_glossy(0.9f, false, beckmann);
    const double correlated = furnace_glossy(0.9f, true, beckmann);
    EXPECT_GT(correlated, separable * (beckmann ? 1.0 : 1.01)) << beckmann;
    EXPECT_LT(correlated, 1.01) << beckmann;
  }
  // Nearly smooth, nothing is shadowed in either model.
  EXPECT_NEAR(furnace_glossy(0.05f, true, false), furnace_glossy(0.05f, false, false), 0.01);
}

TEST(Tracer, MicrofacetGlassFresnelKeepsEnergyAndReflectsLessAtTheRim) {
  // Cycles 4.0's rough glass: reflection F(h) and refraction 1 - F(h) of each
  // microfacet, instead of F and 1 - F of the shading normal. In a white world
  // the sphere still returns at most what reaches it; its rim, where the
  // normal's Fresnel is largest, reflects less (h lies between wo and wi).
  double reflected[2];
  for (const bool per_microfacet : {false, true}) {
    Scene s;
    Closure glass = closure(Closure::Type::glass, {1, 1, 1}, 0.3f);
    glass.ior = 1.5f;
    s.materials = {of({glass})};
    add_sphere(s, {0, 0, 0}, 1, 0);
    s.world_radiance = {1, 1, 1};
    s.camera = top_camera(5, 2.0f, 16);
    s.closure_model.height_correlated_shadowing = per_microfacet;
    s.closure_model.microfacet_glass_fresnel = per_microfacet;
    TraceOptions o = options(128);
    o.max_bounces = 64;
    const TraceResult r = trace_lpe(s, {"L.*E", "LSE"}, o);
    // Over the sphere's disk (pi / 4 of the square): all of it, no more.
    EXPECT_LT(mean(r.images[0]), 1.02) << per_microfacet;
    EXPECT_GT(mean(r.images[0]), 0.85) << per_microfacet;
    reflected[per_microfacet] = mean(r.images[1]);
  }
  EXPECT_LT(reflected[1], reflected[0] * 0.97);
}

TEST(Tracer, WorldRayVisibility) {
  // A world invisible to diffuse rays lights nothing diffusely.
  Scene s;
  s.materials = {lambert(1.0f)};
  add_floor(s, 1000, 0);
  s.world_radiance = {0.7f, 0.7f, 0.7f};
  s.world_visibility = kVisibleAll & ~kVisibleDiffuse;
  s.camera = top_camera(5, 2, 8);
  const TraceResult r = trace_lpe(s, {"LDE"}, options(16));
  EXPECT_EQ(mean(r.images[0]), 0.0);
}

TEST(Tracer, FilterGlossyBlursMirrorsAfterADiffuseBounce) {
  // A point light (radius 0: no ray can hit it) seen in a mirror from a
  // diffuse floor: LS+DE is impossible, unless Filter Glossy blurs the
  // mirror after the diffuse bounce so that light sampling reaches it.
  Scene s;
  s.materials = {lambert(0.8f)};
  add_floor(s, 20, 0);
  Material mirror;  // Principled metal, roughness 0: a mirror that Filter Glossy may blur
  mirror.base_color = {0.9f, 0.9f, 0.9f};
  mirror.metallic = 1;
  mirror.roughness = 0;
  s.materials.push_back(mirror);
  add_sphere(s, {0, 0, 1.5f}, 0.5f, 1);
  Light point;
  point.type = Light::Type::point;
  point.position = {1, 0, 4};
  point.intensity = {50, 50, 50};
  s.lights = {point};
  s.camera = top_camera(6, 6, 16);
  TraceOptions o = options(32);
  EXPECT_EQ(mean(trace_lpe(s, {"LS+DE"}, o).images[0]), 0.0);
  o.filter_glossy = 1;
  EXPECT_GT(mean(trace_lpe(s, {"LS+DE"}, o).images[0]), 0.0);
}

TEST(Tracer, SameResultForAnyThreadCountWithClosuresMapsAndFilters) {
  // Mixed closures with a Fresnel factor, a transparent sheet, rough glass,
  // a soft point light, an environment map, Filter Glossy and Cycles' pixel filter.
  Scene s = sun_scene(0.9f);
  Closure d = closure(Closure::Type::diffuse, {0.6f, 0.5f, 0.4f}, 0.3f);
  Closure g = closure(Closure::Type::glossy, {1, 1, 1}, 0.2f);
  Factor f;
  f.kind = Factor::Kind::fresnel;
  f.value = 1.5f;
  d.factors = {f};
  d.factors[0].invert = true;
  g.factors = {f};
  Closure glass = closure(Closure::Type::glass, {1, 1, 1}, 0.2f);
  s.materials = {of({d, g}), of({glass}), of({closure(Closure::Type::transparent, {0.5f, 0.5f, 0.5f})})};
  add_floor(s, 100, 0);
  s.triangle_materials = {0, 0, 0, 0};  // the sun scene's floor and this one
  add_sphere(s, {0, 0, 0.5f}, 0.5f, 1, 12, 24);
  add_quad(s, {-1, -1, 1.5f}, {1, -1, 1.5f}, {1, 1, 1.5f}, {-1, 1, 1.5f}, 2);
  Light point;
  point.type = Light::Type::point;
  point.position = {1, 1, 3};
  point.radius = 0.5f;
  point.intensity = {20, 20, 20};
  s.lights.push_back(point);
  Image map(16, 8, 4);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 3; ++c) map.at(x, y, c) = 0.1f * float(x % 4 + y);
  s.textures = {map};
  s.world_map = 0;
  s.world_radiance = {1, 1, 1};
  TraceOptions one = options(8), two = options(8);
  for (TraceOptions* o : {&one, &two}) {
    o->seed = 11;
    o->filter_glossy = 1;
    o->pixel_filter = TraceOptions::PixelFilter::blackman_harris;
    o->filter_width = 1.5f;
  }
  one.threads = 1;
  two.threads = 2;
  const std::vector<std::string> expressions = {"L.*E", "LDE", "LSE", "L.*TE"};
  const TraceResult a = trace_lpe(s, expressions, one);
  const TraceResult b = trace_lpe(s, expressions, two);
  for (std::size_t k = 0; k < expressions.size(); ++k) {
    EXPECT_EQ(std::memcmp(a.images[k].data(), b.images[k].data(), a.images[k].pixel_count() * 3 * sizeof(float)),
              0) << expressions[k];
    EXPECT_GT(mean(a.images[k]), 0.0) << expressions[k];
  }
}

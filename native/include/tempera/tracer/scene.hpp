#pragma once
// The light-path tracer's scene: plain triangles, materials, lights, world and
// camera in world space and physical units. Nothing here knows Blender; the
// add-on's exporter converts Blender's data into exactly this.
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

struct Float3 {
  float x = 0, y = 0, z = 0;
  float operator[](int i) const { return i == 0 ? x : i == 1 ? y : z; }
};
inline Float3 operator+(Float3 a, Float3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Float3 operator-(Float3 a, Float3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Float3 operator-(Float3 a) { return {-a.x, -a.y, -a.z}; }
inline Float3 operator*(Float3 a, Float3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline Float3 operator*(Float3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline Float3 operator*(float s, Float3 a) { return a * s; }
inline Float3 operator/(Float3 a, float s) { return a * (1.0f / s); }
inline Float3& operator+=(Float3& a, Float3 b) { return a = a + b; }
inline Float3& operator*=(Float3& a, Float3 b) { return a = a * b; }
inline float dot(Float3 a, Float3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Float3 cross(Float3 a, Float3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(Float3 a) { return std::sqrt(dot(a, a)); }
inline Float3 normalize(Float3 a) { return a / length(a); }
inline float max_component(Float3 a) { return std::fmax(a.x, std::fmax(a.y, a.z)); }
inline float luminance(Float3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// A texture lookup: image `image` of Scene::textures (RGBA, row 0 at the top,
// v = 1), read bilinearly with repeat at the UV
//   (u', v') = (uv[0] u + uv[1] v + uv[2], uv[3] u + uv[4] v + uv[5])
// (the exporter folds Blender's Mapping node into this). Scalars read one
// channel: 0..3 = R, G, B, A, 4 = luminance (Blender's colour-to-float).
struct TextureRef {
  int image = -1;  // -1: no texture
  std::array<float, 6> uv{1, 0, 0, 0, 1, 0};
  int channel = 4;
  bool valid() const { return image >= 0; }
};

// One factor of a closure's weight; a closure is weighted by the product of
// its factors (a Mix Shader multiplies the closures of its first shader by
// 1 - fac and those of its second by fac, each clamped to [0, 1]).
struct Factor {
  enum class Kind {
    constant,       // value
    texture,        // the texture's scalar
    fresnel,        // Fresnel node: dielectric Fresnel of IOR `value` (inverted on back faces)
    layer_fresnel,  // Layer Weight's Fresnel output, blend `value`
    layer_facing,   // Layer Weight's Facing output, blend `value`
  } kind = Kind::constant;
  float value = 1;
  TextureRef texture;
  bool invert = false;  // the factor is 1 - x
};

// One BSDF, emission or transparency term of a Cycles shader, as Blender's
// shader nodes produce them. Events: diffuse and translucent are D, glossy and
// reflections S, refraction T; transparent is no event (the path goes on).
struct Closure {
  enum class Type {
    principled,   // Principled BSDF: Cycles 3.x v1 (Disney diffuse, GGX with its Fresnel, smooth glass,
                  // clearcoat), or Cycles 4 v2's layers with ClosureModel::principled_v2
    diffuse,      // Lambert, or Oren-Nayar with a roughness
    glossy,       // microfacet reflection tinted by color, no Fresnel (Glossy, Anisotropic)
    glass,        // smooth dielectric: Fresnel reflection S + refraction T, both tinted
    refraction,   // smooth refraction only, tinted, no Fresnel
    translucent,  // Lambert through the surface
    transparent,  // straight through, tinted (transparent bounces)
    emission,     // radiance color x weight, both sides
  } type = Type::diffuse;
  enum class Distribution { ggx, beckmann, sharp } distribution = Distribution::ggx;
  Float3 weight{1, 1, 1};  // constant part of the weight (e.g. emission strength)
  std::vector<Factor> factors;
  Float3 color{0.8f, 0.8f, 0.8f};
  TextureRef color_texture;  // replaces color (rgb)
  float roughness = 0;       // Blender's: alpha = roughness^2, below 0.01 singular; Diffuse: Oren-Nayar sigma
  TextureRef roughness_texture;  // replaces roughness (its channel)
  float ior = 1.45f;
  // Principled only:
  float metallic = 0, specular = 0.5f, transmission = 0;
  float subsurface = 0;  // mixes subsurface_color into the diffuse colour (scattering itself not traced)
  Float3 subsurface_color{0.8f, 0.8f, 0.8f};
  float clearcoat = 0, clearcoat_roughness = 0.03f;  // a GGX lobe, F0 0.04, weight 0.25 clearcoat
  // Principled v2 (ClosureModel::principled_v2) reads clearcoat and
  // clearcoat_roughness as Coat Weight and Coat Roughness, and these:
  float specular_ior_level = 0.5f;     // scales the F0 the IOR gives by 2 x level
  Float3 specular_tint{1, 1, 1};       // dielectric F0's tint; metal's F82 tint
  float coat_ior = 1.5f;
  Float3 coat_tint{1, 1, 1};           // absorption of the coat at normal incidence
  bool multiscatter = false;           // Multiscatter GGX: the energy single scattering loses is restored
};

// A surface. With `closures` empty it is the single Principled closure given
// by the fields below (the original scene format); otherwise the closures
// are used and only `closures` matters.
struct Material {
  Float3 base_color{0.8f, 0.8f, 0.8f};
  float metallic = 0;
  float specular = 0.5f;   // Blender's: F0 = 0.08 * specular for dielectrics
  float roughness = 0.5f;  // GGX alpha = roughness^2; below 0.01 a perfect mirror
  float transmission = 0;
  float ior = 1.45f;
  Float3 emission{0, 0, 0};  // radiance W/m^2/sr, strength included; both sides emit
  // Optional linear RGB (H, W, 3) texture; when present it replaces base_color.
  // Sampled bilinearly with repeat; UV (0,0) is the bottom-left corner, so
  // image row 0 is v = 1 (as Blender shows images).
  Image base_color_texture;
  std::vector<Closure> closures;
};

struct Light {
  enum class Type { point, spot, sun, area } type = Type::point;
  enum class Shape { rect, disk } shape = Shape::rect;
  Float3 position;        // point, spot
  Float3 direction;       // spot: where it shines; sun: towards the light
  float radius = 0;       // point, spot: a disk of this radius facing the shaded point
  Float3 intensity;       // point, spot: W/sr
  float spot_half_angle = 0.7853982f;  // spot cone half-angle, radians
  float spot_blend = 0;                // spot: Blender's smoothstep blend in [0, 1]
  // spot: Cycles 3.x also weights by the cosine to the axis; 4.0 dropped it
  // (the smoothstep alone).
  bool spot_axis_cosine = true;
  float angle = 0;        // sun: angular diameter, radians
  Float3 irradiance;      // sun: W/m^2 on a surface facing the sun
  Float3 center, axis_u, axis_v, normal;  // area: unit axes; emits along +normal only
  float size_u = 1, size_v = 1;           // area: full extents (disk: diameters)
  Float3 radiance;        // area: W/m^2/sr
  // point, spot: how the radius is sampled: a disk facing the shaded point
  // (Cycles up to 3.6) or a sphere (Cycles 4.0 on); radiance I / (pi r^2) either way.
  enum class SoftShape { disk, sphere } soft_shape = SoftShape::disk;
  // Which bounces see the light (Blender's ray visibility of the light
  // object): bits of Visibility; cast_shadow false: not occluded.
  unsigned visibility = 0xFFu;
  bool cast_shadow = true;
  // Cycles' Light > Max Bounces: next-event estimation samples the light only
  // at vertices with at most this many bounces before them (0: direct light
  // only). BSDF rays still reach it beyond that, weighted by MIS as if it were
  // sampled, as Cycles does: most of its indirect light is then gone.
  int max_bounces = 1024;
  // Cycles' Light > Multiple Importance: off, BSDF rays pass through the light
  // (camera rays still see an area light) and its samples take full weight.
  bool multiple_importance = true;
};

// Ray visibility bits (objects and lights), as Blender's Ray Visibility panel.
enum Visibility : unsigned {
  kVisibleCamera = 1u, kVisibleDiffuse = 2u, kVisibleGlossy = 4u, kVisibleTransmission = 8u, kVisibleShadow = 16u,
  kVisibleAll = 31u,
};

// Camera projection. The camera looks down its local -Z with +Y up; the
// 4x4 row-major camera_to_world matrix maps camera space to world space
// (Blender's matrix_world of the camera object, with unit scale).
// Pixel (x, y) has rows top-down and its centre at (x + 0.5, y + 0.5); with
// ndc_x = 2 (x + 0.5) / width - 1 and ndc_y = 1 - 2 (y + 0.5) / height:
//   perspective:  ray from the camera origin along camera-space
//                 (ndc_x * tan_half_fov_x + 2 * shift_x * t,
//                  ndc_y * tan_half_fov_y + 2 * shift_y * t, -1)
//                 where t = tan_half_fov of the larger image side (Blender's
//                 sensor fit AUTO: shift is in units of the larger side);
//   orthographic: ray along camera-space -Z from
//                 (ndc_x * ortho_width / 2 + shift_x * s,
//                  ndc_y * ortho_height / 2 + shift_y * s, 0)
//                 where s = max(ortho_width, ortho_height) (Blender's ortho_scale).
// Geometry counts only between clip_start and clip_end, measured along the
// view axis (depth) as Blender clips; beyond that rays see the world.
struct Camera {
  enum class Type { perspective, orthographic } type = Type::perspective;
  std::array<float, 16> camera_to_world{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  int width = 0, height = 0;
  float tan_half_fov_x = 0.5f, tan_half_fov_y = 0.5f;
  float shift_x = 0, shift_y = 0;
  float ortho_width = 1, ortho_height = 1;
  float clip_start = 0.1f, clip_end = 1000.0f;
};

// Which Cycles' microfacet closures the tracer renders (the exporter knows the
// Blender version; the tracer does not). Cycles 3.x: separable Smith shadowing
// G1(i) G1(o), and rough glass as two closures whose reflection is weighted by
// the Fresnel of the shading normal. Cycles 4.0+: height-correlated Smith
// shadowing 1 / (1 + Lambda(i) + Lambda(o)) (Heitz 2014), and rough glass as one
// closure with the Fresnel of each microfacet normal.
struct ClosureModel {
  bool height_correlated_shadowing = false;
  bool microfacet_glass_fresnel = false;
  // Principled closures are Cycles 4.0's Principled v2 (principled_v2.hpp):
  // coat over metal, glass and a dielectric specular layer over Lambertian
  // diffuse, each layer weighted by 1 - the albedo of the layers above;
  // false: Cycles 3.x's v1 (Disney diffuse, Principled Fresnel, clearcoat).
  bool principled_v2 = false;
  // Diffuse BSDF roughness is Cycles 4.3's Oren-Nayar: Fujii's form with other
  // constants plus the OpenPBR multiple-scattering term that keeps its energy
  // (bsdf.cpp); false: Cycles 3.x's Fujii form, which loses energy with roughness.
  bool energy_preserving_oren_nayar = false;
};

struct Scene {
  std::vector<Float3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::int32_t> triangle_materials;  // index into materials, per triangle
  std::vector<Float3> normals;                   // optional: 3 per triangle (per corner)
  std::vector<std::array<float, 2>> uvs;         // optional: 3 per triangle (per corner)
  std::vector<Material> materials;
  std::vector<Light> lights;
  Float3 world_radiance;  // constant, W/m^2/sr; multiplies world_map if there is one
  // Optional equirectangular environment (Blender's Environment Texture):
  // an index into textures. A world direction d is turned into the map's
  // frame by world_rotation (row-major 3x3 M, d' = M d: the rotation of a
  // Point-type Mapping node in front of the texture), then read at
  // u = 0.5 - atan2(y', x') / (2 pi), v = 0.5 + asin(z') / pi.
  int world_map = -1;
  std::array<float, 9> world_rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};
  // Which rays see the world (bits of Visibility: Blender's World > Ray Visibility).
  unsigned world_visibility = kVisibleAll;
  std::vector<Image> textures;  // RGBA float images referenced by TextureRef and world_map
  // Optional per-triangle ray visibility (bits of Visibility); empty: all visible.
  std::vector<std::uint8_t> triangle_visibility;
  Camera camera;
  ClosureModel closure_model;  // Cycles 3.x's by default
};

// Throws ValueError naming the first problem: non-finite numbers, indices out
// of range, wrong per-corner array sizes, an empty image, bad light shapes.
void validate_scene(const Scene& scene);

// Base colour at a surface point: the texture (bilinear, repeat) if any.
Float3 base_color_at(const Material& material, float u, float v);

// Bilinear, repeating lookup of an RGBA image at (u, v), v = 1 at row 0.
std::array<float, 4> sample_texture(const Image& image, float u, float v);
Float3 texture_rgb(const Scene& scene, const TextureRef& ref, float u, float v);
float texture_scalar(const Scene& scene, const TextureRef& ref, float u, float v);

}  // namespace tempera

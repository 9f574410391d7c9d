#include "tempera/tracer/scene.hpp"

#include <cmath>
#include <string>

#include "tempera/engine/error.hpp"

namespace tempera {
namespace {

bool finite(Float3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The message is only built on failure: this runs once per vertex.
template <typename... Parts>
void require(bool ok, const Parts&... message) {
  if (!ok) throw ValueError(concat("scene: ", message...));
}

void require_finite3(Float3 v, const std::string& what) { require(finite(v), what + " is not finite"); }

void require_unit(Float3 v, const std::string& what) {
  require_finite3(v, what);
  require(std::fabs(length(v) - 1.0f) < 1e-3f, what + " must be a unit vector");
}

void validate_material(const Material& m, const std::string& what) {
  require_finite3(m.base_color, what + " base_color");
  require_finite3(m.emission, what + " emission");
  for (float f : {m.metallic, m.specular, m.roughness, m.transmission, m.ior})
    require(std::isfinite(f), what + " has a non-finite parameter");
  require(m.ior > 0, what + " ior must be positive");
  if (!m.base_color_texture.empty()) {
    require(m.base_color_texture.channels() == 3, what + " base_color_texture must be (H, W, 3)");
    require_finite(m.base_color_texture.view(), what + " base_color_texture");
  }
}

void validate_texture_ref(const TextureRef& t, std::size_t textures, const std::string& what) {
  if (!t.valid()) return;
  require(std::size_t(t.image) < textures, what, " uses texture ", t.image, " but there are ", textures, " textures");
  for (float f : t.uv) require(std::isfinite(f), what, " has a non-finite UV transform");
  require(t.channel >= 0 && t.channel <= 4, what, " channel must be in [0, 4]");
}

void validate_closures(const Material& m, std::size_t textures, const std::string& what) {
  for (std::size_t i = 0; i < m.closures.size(); ++i) {
    const Closure& c = m.closures[i];
    const std::string name = concat(what, " closure ", i);
    require_finite3(c.weight, name + " weight");
    require_finite3(c.color, name + " color");
    for (float f : {c.roughness, c.ior, c.metallic, c.specular, c.transmission})
      require(std::isfinite(f), name + " has a non-finite parameter");
    require(c.ior > 0, name + " ior must be positive");
    validate_texture_ref(c.color_texture, textures, name + " color_texture");
    validate_texture_ref(c.roughness_texture, textures, name + " roughness_texture");
    for (const Factor& f : c.factors) {
      require(std::isfinite(f.value), name + " has a non-finite factor");
      if (f.kind == Factor::Kind::texture) {
        require(f.texture.valid(), name + " has a texture factor without a texture");
        validate_texture_ref(f.texture, textures, name + " factor");
      }
    }
  }
}

void validate_light(const Light& l, const std::string& what) {
  require(l.max_bounces >= 0, concat(what, " max_bounces must be >= 0, got ", l.max_bounces));
  switch (l.type) {
    case Light::Type::spot:
      require_unit(l.direction, what + " direction");
      require(std::isfinite(l.spot_half_angle) && l.spot_half_angle > 0, what + " spot_half_angle must be > 0");
      require(std::isfinite(l.spot_blend) && l.spot_blend >= 0 && l.spot_blend <= 1,
              what + " spot_blend must be in [0, 1]");
      [[fallthrough]];
    case Light::Type::point:
      require_finite3(l.position, what + " position");
      require_finite3(l.intensity, what + " intensity");
      require(std::isfinite(l.radius) && l.radius >= 0, what + " radius must be >= 0");
      break;
    case Light::Type::sun:
      require_unit(l.direction, what + " direction");
      require_finite3(l.irradiance, what + " irradiance");
      require(std::isfinite(l.angle) && l.angle >= 0 && l.angle < 3.1415f, what + " angle must be in [0, pi)");
      break;
    case Light::Type::area:
      require_finite3(l.center, what + " center");
      require_unit(l.axis_u, what + " axis_u");
      require_unit(l.axis_v, what + " axis_v");
      require_unit(l.normal, what + " normal");
      require_finite3(l.radiance, what + " radiance");
      require(std::isfinite(l.size_u) && std::isfinite(l.size_v) && l.size_u > 0 && l.size_v > 0,
              what + " size_u and size_v must be > 0");
      break;
  }
}

void validate_camera(const Camera& c) {
  require(c.width > 0 && c.height > 0, "camera size ", c.width, "x", c.height, " is empty");
  for (float f : c.camera_to_world) require(std::isfinite(f), "camera camera_to_world is not finite");
  {  // A singular rotation/scale part has no ray directions (Embree asserts on them).
    const auto& m = c.camera_to_world;  // row-major 4x4
    auto at = [&](int r, int k) { return double(m[4 * r + k]); };
    const double det = at(0, 0) * (at(1, 1) * at(2, 2) - at(1, 2) * at(2, 1)) -
                       at(0, 1) * (at(1, 0) * at(2, 2) - at(1, 2) * at(2, 0)) +
                       at(0, 2) * (at(1, 0) * at(2, 1) - at(1, 1) * at(2, 0));
    double scale = 1.0;
    for (int k = 0; k < 3; ++k)
      scale *= std::sqrt(at(0, k) * at(0, k) + at(1, k) * at(1, k) + at(2, k) * at(2, k));
    require(scale > 0 && std::abs(det) > 1e-6 * scale,
            "camera camera_to_world is singular (its 3x3 part has determinant ", det,
            "): a camera scaled to zero along an axis has no view");
  }
  for (float f : {c.shift_x, c.shift_y, c.clip_start, c.clip_end})
    require(std::isfinite(f), "camera has a non-finite parameter");
  require(c.clip_start >= 0 && c.clip_end > c.clip_start, "camera needs 0 <= clip_start < clip_end");
  if (c.type == Camera::Type::perspective)
    require(std::isfinite(c.tan_half_fov_x) && std::isfinite(c.tan_half_fov_y) && c.tan_half_fov_x > 0 &&
                c.tan_half_fov_y > 0,
            "camera tan_half_fov_x and tan_half_fov_y must be > 0");
  else
    require(std::isfinite(c.ortho_width) && std::isfinite(c.ortho_height) && c.ortho_width > 0 &&
                c.ortho_height > 0,
            "camera ortho_width and ortho_height must be > 0");
}

}  // namespace

void validate_scene(const Scene& s) {
  for (std::size_t i = 0; i < s.vertices.size(); ++i)
    require(finite(s.vertices[i]), "vertex ", i, " is not finite");
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
    for (std::uint32_t v : s.triangles[t])
      require(v < s.vertices.size(), "triangle ", t, " uses vertex ", v, " but there are only ", s.vertices.size(),
              " vertices");
  require(s.triangle_materials.size() == s.triangles.size(),
          "triangle_materials has ", s.triangle_materials.size(), " entries for ", s.triangles.size(), " triangles");
  for (std::size_t t = 0; t < s.triangle_materials.size(); ++t) {
    const auto m = s.triangle_materials[t];
    require(m >= 0 && std::size_t(m) < s.materials.size(),
            "triangle ", t, " uses material ", m, " but there are ", s.materials.size(), " materials");
  }
  require(s.normals.empty() || s.normals.size() == 3 * s.triangles.size(), "normals must be (T, 3, 3)");
  for (std::size_t i = 0; i < s.normals.size(); ++i)
    require(finite(s.normals[i]) && length(s.normals[i]) > 0, "normal ", i / 3, ",", i % 3, " is invalid");
  require(s.uvs.empty() || s.uvs.size() == 3 * s.triangles.size(), "uvs must be (T, 3, 2)");
  for (std::size_t i = 0; i < s.uvs.size(); ++i)
    require(std::isfinite(s.uvs[i][0]) && std::isfinite(s.uvs[i][1]), "uv ", i / 3, ",", i % 3, " is not finite");
  for (std::size_t i = 0; i < s.materials.size(); ++i) validate_material(s.materials[i], concat("material ", i));
  for (std::size_t i = 0; i < s.lights.size(); ++i) validate_light(s.lights[i], concat("light ", i));
  for (std::size_t i = 0; i < s.materials.size(); ++i)
    validate_closures(s.materials[i], s.textures.size(), concat("material ", i));
  for (std::size_t i = 0; i < s.textures.size(); ++i) {
    require(!s.textures[i].empty() && s.textures[i].channels() == 4, "texture ", i, " must be (H, W, 4)");
    require_finite(s.textures[i].view(), concat("texture ", i));
  }
  require_finite3(s.world_radiance, "world radiance");
  require(s.world_map < 0 || std::size_t(s.world_map) < s.textures.size(), "world map ", s.world_map,
          " is not a texture");
  for (float f : s.world_rotation) require(std::isfinite(f), "world rotation is not finite");
  require(s.triangle_visibility.empty() || s.triangle_visibility.size() == s.triangles.size(),
          "triangle_visibility has ", s.triangle_visibility.size(), " entries for ", s.triangles.size(), " triangles");
  validate_camera(s.camera);
}

namespace {

// Bilinear, repeating lookup of any channel count; v runs bottom-up while rows run top-down.
template <int N>
std::array<float, N> bilinear(const Image& tex, float u, float v) {
  const int w = tex.width(), h = tex.height(), c = tex.channels();
  // Wrapping first keeps the texel indices small whatever the UVs.
  u -= std::floor(u);
  v -= std::floor(v);
  const float fx = u * float(w) - 0.5f, fy = (1.0f - v) * float(h) - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
  const int x0 = wrap(int(x0f), w), x1 = wrap(int(x0f) + 1, w);
  const int y0 = wrap(int(y0f), h), y1 = wrap(int(y0f) + 1, h);
  std::array<float, N> out{};
  const float* p00 = tex.pixel(x0, y0);
  const float* p10 = tex.pixel(x1, y0);
  const float* p01 = tex.pixel(x0, y1);
  const float* p11 = tex.pixel(x1, y1);
  for (int k = 0; k < N && k < c; ++k)
    out[k] = (p00[k] * (1 - ax) + p10[k] * ax) * (1 - ay) + (p01[k] * (1 - ax) + p11[k] * ax) * ay;
  return out;
}

std::array<float, 2> mapped_uv(const TextureRef& r, float u, float v) {
  return {r.uv[0] * u + r.uv[1] * v + r.uv[2], r.uv[3] * u + r.uv[4] * v + r.uv[5]};
}

}  // namespace

std::array<float, 4> sample_texture(const Image& image, float u, float v) { return bilinear<4>(image, u, v); }

Float3 texture_rgb(const Scene& scene, const TextureRef& ref, float u, float v) {
  const auto uv = mapped_uv(ref, u, v);
  const auto t = bilinear<4>(scene.textures[ref.image], uv[0], uv[1]);
  return {t[0], t[1], t[2]};
}

float texture_scalar(const Scene& scene, const TextureRef& ref, float u, float v) {
  const auto uv = mapped_uv(ref, u, v);
  const auto t = bilinear<4>(scene.textures[ref.image], uv[0], uv[1]);
  return ref.channel < 4 ? t[ref.channel] : luminance({t[0], t[1], t[2]});
}

Float3 base_color_at(const Material& m, float u, float v) {
  const Image& tex = m.base_color_texture;
  if (tex.empty()) return m.base_color;
  const auto t = bilinear<3>(tex, u, v);
  return {t[0], t[1], t[2]};
}

}  // namespace tempera

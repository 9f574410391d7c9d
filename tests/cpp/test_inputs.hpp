#pragma once
// Inputs shared by the C++ tests: procedural images and tracer scenes.
#include <cmath>
#include <cstdint>
#include <random>

#include "tempera/tracer/embree_tracer.hpp"
#include "tempera/engine/image.hpp"
#include "tempera/engine/patch_distance.hpp"
#include "tempera/engine/patchmatch.hpp"

namespace tempera::test_inputs {

// Uniform noise in [0, 1), reproducible from the seed.
inline Image noise_texture(int w, int h, int c, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Image img(w, h, c);
  for (std::size_t i = 0; i < img.pixel_count() * c; ++i) img.data()[i] = u(rng);
  return img;
}

// Features of values k / 1000 (k in 0..999), reproducible from the seed.
inline FeatureImage random_features(int w, int h, int channels, unsigned seed) {
  std::mt19937 rng(seed);
  FeatureImage f(w, h, channels);
  for (float& v : f.data) v = float(rng() % 1000) * 1e-3f;
  return f;
}

// Search constraints where every source pixel at least `border` from the
// edge of a w x h exemplar may be a patch centre, and `targets` target
// pixels are active.
inline SearchConstraints inner_sources(int w, int h, int border, std::size_t targets) {
  SearchConstraints cons;
  cons.source_valid.assign(std::size_t(w) * h, 0);
  for (int y = border; y < h - border; ++y)
    for (int x = border; x < w - border; ++x) cons.source_valid[std::size_t(y) * w + x] = 1;
  cons.target_active.assign(targets, 1);
  cons.finalize();
  return cons;
}

// A UV sphere of outward-facing triangles.
inline void add_sphere(Scene& s, Float3 centre, float radius, int material, int rings = 48, int segments = 96) {
  constexpr float kPi = 3.14159265358979f;
  const auto base = std::uint32_t(s.vertices.size());
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const float theta = kPi * float(i) / float(rings), phi = 2 * kPi * float(j) / float(segments);
      s.vertices.push_back(centre + Float3{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                           std::cos(theta)} * radius);
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const std::uint32_t a = base + i * segments + j, b = base + i * segments + (j + 1) % segments;
      const std::uint32_t c = a + segments, d = b + segments;
      s.triangles.push_back({a, c, d});
      s.triangles.push_back({a, d, b});
      s.triangle_materials.insert(s.triangle_materials.end(), {material, material});
    }
}

// Orthographic camera at height z looking straight down at a square of side `size`.
inline Camera top_camera(float z, float size, int pixels) {
  Camera c;
  c.type = Camera::Type::orthographic;
  c.camera_to_world = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, z, 0, 0, 0, 1};
  c.width = c.height = pixels;
  c.ortho_width = c.ortho_height = size;
  c.clip_start = 0.01f;
  return c;
}

}  // namespace tempera::test_inputs

#include "lights.hpp"

#include <cmath>
#include <limits>

namespace tempera::tracer {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

// Cycles' spot attenuation: zero outside the cone, smoothstep over the blend
// region, times the cosine to the axis in Cycles 3.x (spot_axis_cosine).
float spot_attenuation(const Light& l, Float3 from_light) {
  const float cos_a = dot(l.direction, from_light), cos_edge = std::cos(l.spot_half_angle);
  if (cos_a <= cos_edge) return 0;
  const float smooth = (1 - cos_edge) * l.spot_blend, t = cos_a - cos_edge;
  float attenuation = l.spot_axis_cosine ? cos_a : 1.0f;
  if (smooth > 0 && t < smooth) {
    const float x = t / smooth;
    attenuation *= x * x * (3 - 2 * x);
  }
  return attenuation;
}

}  // namespace

float area_of(const Light& l) {
  return l.shape == Light::Shape::rect ? l.size_u * l.size_v : kPi * l.size_u * l.size_v / 4;
}

bool to_area_sample(Float3 to_x, Float3 normal, Float3 radiance, float pdf_area, LightSample& out, bool two_sided) {
  const float d2 = dot(to_x, to_x);
  if (!(d2 > 0)) return false;
  out.distance = std::sqrt(d2);
  out.wi = to_x / out.distance;
  float cos_l = -dot(normal, out.wi);
  if (two_sided) cos_l = std::fabs(cos_l);
  if (cos_l <= 0) return false;
  out.pdf = pdf_area * d2 / cos_l;
  out.radiance = radiance / out.pdf;
  return true;
}

bool sample_light(const Light& l, Float3 p, float u1, float u2, LightSample& out) {
  switch (l.type) {
    case Light::Type::point:
    case Light::Type::spot: {
      const Float3 towards = l.position - p;
      const float d0 = length(towards);
      if (!(d0 > 0)) return false;
      const Frame frame(towards / d0);
      if (l.soft_shape == Light::SoftShape::sphere && l.radius > 0) {
        // A sphere of radiance I / (pi r^2): uniform in the cone it subtends.
        if (d0 <= l.radius) return false;
        const float sin_max = l.radius / d0, cos_max = std::sqrt(std::fmax(0.0f, 1 - sin_max * sin_max));
        out.wi = frame.to_world(sample_cone(u1, u2, cos_max));
        const float solid_angle = 2 * kPi * (1 - cos_max);
        // Distance to the sphere along wi.
        const float b = dot(out.wi, towards), c = d0 * d0 - l.radius * l.radius;
        out.distance = b - std::sqrt(std::fmax(0.0f, b * b - c));
        out.point = p + out.wi * out.distance;
        out.radiance = l.intensity * (solid_angle / (kPi * l.radius * l.radius));
        out.pdf = 1 / solid_angle;
      } else {
        // A disk of the light's radius facing p (Cycles 3.x's soft point lights).
        const auto disk = sample_disk(u1, u2);
        const Float3 x = l.position + (frame.t * disk[0] + frame.b * disk[1]) * l.radius;
        const Float3 to_x = x - p;
        out.distance = length(to_x);
        out.wi = to_x / out.distance;
        out.point = x;
        // Radiance I / (pi r^2) over the pdf 1 / (pi r^2) per area, to solid angle.
        const float cos_l = dot(frame.n, out.wi);
        out.radiance = l.intensity * (cos_l / (out.distance * out.distance));
        // A disk BSDF rays can hit too (l.radius > 0): its pdf per solid angle.
        out.pdf = l.radius > 0 && cos_l > 0 ? out.distance * out.distance / (kPi * l.radius * l.radius * cos_l) : 0;
      }
      if (l.type == Light::Type::spot) {
        const float attenuation = spot_attenuation(l, -out.wi);
        if (!(attenuation > 0)) return false;
        out.radiance = out.radiance * attenuation;
      }
      return true;
    }
    case Light::Type::sun: {
      // Uniform in the sun's cone; irradiance already is radiance over pdf.
      out.wi = Frame(l.direction).to_world(sample_cone(u1, u2, std::cos(l.angle / 2)));
      out.distance = kInfinity;
      out.radiance = l.irradiance;
      out.pdf = 0;
      return true;
    }
    case Light::Type::area: {
      float a, b;
      if (l.shape == Light::Shape::rect) {
        a = u1 - 0.5f, b = u2 - 0.5f;
      } else {
        const auto disk = sample_disk(u1, u2);
        a = disk[0] / 2, b = disk[1] / 2;
      }
      const Float3 x = l.center + l.axis_u * (a * l.size_u) + l.axis_v * (b * l.size_v);
      out.point = x;
      return to_area_sample(x - p, l.normal, l.radiance, 1 / area_of(l), out);
    }
  }
  return false;
}

bool cross_soft_light(const Light& l, Float3 o, Float3 d, float t_near, float t_far, float& t, float& pdf,
                      Float3& radiance) {
  if (!(l.radius > 0)) return false;
  const Float3 to_centre = l.position - o;
  const float d0 = length(to_centre);
  if (!(d0 > 0)) return false;
  const float r2 = l.radius * l.radius;
  if (l.soft_shape == Light::SoftShape::sphere) {
    if (!(d0 > l.radius)) return false;  // inside the sphere: not modelled (NEE skips it too)
    const float b = dot(d, to_centre), c = d0 * d0 - r2, disc = b * b - c;
    if (disc < 0 || b <= 0) return false;
    t = b - std::sqrt(disc);
    const float cos_max = std::sqrt(std::fmax(0.0f, 1 - r2 / (d0 * d0)));
    pdf = 1 / (2 * kPi * (1 - cos_max));
  } else {
    // The disk facing the ray's origin (Cycles 3.x), also from points closer
    // to the light than its radius (a large light near a floor).
    const Float3 n = to_centre / d0;  // from the origin towards the light
    const float cos_l = dot(d, n);
    if (cos_l <= 0) return false;
    t = d0 / cos_l;
    const Float3 q = o + d * t - l.position;
    if (dot(q, q) > r2) return false;
    pdf = t * t / (kPi * r2 * cos_l);
  }
  if (!(t > t_near && t < t_far)) return false;
  radiance = l.intensity / (kPi * r2);
  if (l.type == Light::Type::spot) radiance = radiance * spot_attenuation(l, -d);
  return max_component(radiance) > 0;
}

bool cross_area_light(const Light& l, Float3 o, Float3 d, float t_near, float t_far, float& t, float& pdf) {
  const float cos_l = -dot(d, l.normal);
  if (cos_l <= 0) return false;
  t = dot(l.center - o, l.normal) / dot(d, l.normal);
  if (!(t > t_near && t < t_far)) return false;
  const Float3 q = o + d * t - l.center;
  const float a = 2 * dot(q, l.axis_u) / l.size_u, b = 2 * dot(q, l.axis_v) / l.size_v;
  const bool inside = l.shape == Light::Shape::rect ? std::fabs(a) <= 1 && std::fabs(b) <= 1 : a * a + b * b <= 1;
  if (!inside) return false;
  pdf = t * t / (area_of(l) * cos_l);
  return true;
}

// ---------------------------------------------------------------- world ---

Environment::Environment(const Scene& scene) : scene_(scene) {
  if (scene.world_map < 0) return;
  map_ = &scene.textures[std::size_t(scene.world_map)];
  const int w = map_->width(), h = map_->height();
  // Pixels in proportion to luminance times their solid angle (sin theta).
  std::vector<double> row_weights(std::size_t(h), 0.0);
  columns_.reserve(std::size_t(h));
  for (int y = 0; y < h; ++y) {
    const double sin_theta = std::sin(kPi * (double(y) + 0.5) / double(h));
    std::vector<double> weights(static_cast<std::size_t>(w));
    double sum = 0;
    for (int x = 0; x < w; ++x) {
      const float* p = map_->pixel(x, y);
      // A floor keeps every direction reachable (MIS needs nonzero pdfs where radiance is).
      weights[std::size_t(x)] = (std::max(double(luminance({p[0], p[1], p[2]})), 0.0) + 1e-6) * sin_theta;
      sum += weights[std::size_t(x)];
    }
    row_weights[std::size_t(y)] = sum;
    columns_.emplace_back(weights);
  }
  rows_ = Distribution1D(row_weights);
  if (rows_.empty()) columns_.clear(), rows_ = {};
}

Float3 Environment::to_map(Float3 d) const {
  const auto& r = scene_.world_rotation;
  return {r[0] * d.x + r[1] * d.y + r[2] * d.z, r[3] * d.x + r[4] * d.y + r[5] * d.z,
          r[6] * d.x + r[7] * d.y + r[8] * d.z};
}

Float3 Environment::radiance(Float3 direction) const {
  if (!map_) return scene_.world_radiance;
  const Float3 d = to_map(direction);
  const float u = 0.5f - std::atan2(d.y, d.x) / (2 * kPi);
  const float v = 0.5f + std::asin(std::clamp(d.z, -1.0f, 1.0f)) / kPi;
  const auto t = sample_texture(*map_, u, v);
  return Float3{t[0], t[1], t[2]} * scene_.world_radiance;
}

bool Environment::sample(float u1, float u2, float u3, float u4, LightSample& out) const {
  if (!sampled()) return false;
  float p_row, p_column;
  const std::size_t y = rows_.sample(u1, p_row);
  const std::size_t x = columns_[y].sample(u2, p_column);
  const int w = map_->width(), h = map_->height();
  const float fx = (float(x) + u3) / float(w), fy = (float(y) + u4) / float(h);  // uniform in the pixel
  const float v = 1 - fy, u = fx;
  const float phi = (0.5f - u) * 2 * kPi, theta_z = (v - 0.5f) * kPi;  // elevation
  const Float3 m{std::cos(theta_z) * std::cos(phi), std::cos(theta_z) * std::sin(phi), std::sin(theta_z)};
  // Back from map to world space: the rotation's transpose.
  const auto& r = scene_.world_rotation;
  out.wi = normalize(Float3{r[0] * m.x + r[3] * m.y + r[6] * m.z, r[1] * m.x + r[4] * m.y + r[7] * m.z,
                            r[2] * m.x + r[5] * m.y + r[8] * m.z});
  out.pdf = pdf(out.wi);
  if (!(out.pdf > 0)) return false;
  out.distance = kInfinity;
  out.radiance = radiance(out.wi) / out.pdf;
  return true;
}

float Environment::pdf(Float3 direction) const {
  if (!sampled()) return 0;
  const Float3 d = to_map(direction);
  const float u = 0.5f - std::atan2(d.y, d.x) / (2 * kPi);
  const float v = 0.5f + std::asin(std::clamp(d.z, -1.0f, 1.0f)) / kPi;
  const int w = map_->width(), h = map_->height();
  const int x = std::clamp(int((u - std::floor(u)) * float(w)), 0, w - 1);
  const int y = std::clamp(int((1 - v) * float(h)), 0, h - 1);
  const float sin_theta = std::cos((v - 0.5f) * kPi);
  if (!(sin_theta > 1e-6f)) return 0;
  const float p = rows_.probability(std::size_t(y)) * columns_[std::size_t(y)].probability(std::size_t(x));
  return p * float(w) * float(h) / (2 * kPi * kPi * sin_theta);
}

}  // namespace tempera::tracer

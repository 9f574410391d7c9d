#include "microfacet_albedo.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "bsdf.hpp"
#include "sampling.hpp"

namespace tempera::tracer {
namespace {

constexpr int kRoughnessSize = 32, kMuSize = 32;  // E's grid (Cycles' ggx_E: 32 x 32)
constexpr int kBlendSize = 16;                    // s's grid (Cycles': 16 x 16 x 16)
constexpr int kThetaSteps = 96, kPhiSteps = 48;   // quadrature over the microfacet normals

float grid_value(int i, int size, float lo, float hi) {
  return std::clamp(float(i) / float(size - 1), lo, hi);
}
float ior_from_f0(float f0) {
  const float r = std::sqrt(f0);
  return (1 + r) / (1 - r);
}

float lambda(float cos_v, float alpha2) {
  const float c2 = cos_v * cos_v;
  return 0.5f * (std::sqrt(1 + alpha2 * std::max(0.0f, 1 - c2) / c2) - 1);
}

// The mean of g(cos(wo, h)) over the normals the view sees, weighted either
// by visibility alone (what sampling visible normals averages: the blend s)
// or by the lobe's value over its pdf (the albedo E). Reflections below the
// horizon count as 0, as in sampling. Normals are stepped by the inverse of
// the GGX distribution's cdf of D cos, so a sharp lobe is resolved as well as a rough one.
template <class G>
double visible_normal_mean(float roughness, float mu, bool albedo, G g) {
  const float alpha2 = std::max(roughness * roughness * roughness * roughness, 1e-8f);
  const Float3 wo{std::sqrt(std::max(0.0f, 1 - mu * mu)), 0, mu};
  const float lambda_o = lambda(mu, alpha2);
  double sum = 0;
  for (int i = 0; i < kThetaSteps; ++i) {
    const float u = (float(i) + 0.5f) / float(kThetaSteps);
    const float tan2 = alpha2 * u / (1 - u);
    const float cos_h = 1 / std::sqrt(1 + tan2), sin_h = std::sqrt(std::max(0.0f, 1 - cos_h * cos_h));
    for (int j = 0; j < kPhiSteps; ++j) {  // phi in [0, pi]: the lobe is symmetric about wo's plane
      const float phi = kPi * (float(j) + 0.5f) / float(kPhiSteps);
      const Float3 h{sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h};
      const float cos_oh = dot(wo, h);
      if (cos_oh <= 0) continue;
      const float cos_i = 2 * cos_oh * h.z - mu;  // wi = reflect(wo, h)
      if (cos_i <= 0) continue;
      // h is drawn with pdf D cos_h; visible normals have D_wo = G1(wo) cos_oh D / mu.
      double w = cos_oh / (double(mu) * cos_h * (1 + lambda_o));
      if (albedo) w *= (1 + lambda_o) / (1 + lambda_o + lambda(cos_i, alpha2));  // G2 / G1(wo)
      sum += w * g(cos_oh);
    }
  }
  return sum / double(kThetaSteps * kPhiSteps);
}

struct Tables {
  std::vector<float> e, e_avg, blend;
  Tables() : e(kRoughnessSize * kMuSize), e_avg(kRoughnessSize), blend(kBlendSize * kBlendSize * kBlendSize) {
    const auto one = [](float) { return 1.0f; };
    for (int x = 0; x < kRoughnessSize; ++x) {
      const float r = grid_value(x, kRoughnessSize, 1e-4f, 1);
      for (int y = 0; y < kMuSize; ++y)
        e[y * kRoughnessSize + x] = float(std::min(1.0, visible_normal_mean(r, grid_value(y, kMuSize, 1e-4f, 1), true, one)));
      double avg = 0;  // 2 int E mu dmu, midpoint rule
      constexpr int kSteps = 32;
      for (int k = 0; k < kSteps; ++k) {
        const float mu = (float(k) + 0.5f) / float(kSteps);
        avg += 2.0 * mu * visible_normal_mean(r, mu, true, one) / kSteps;
      }
      e_avg[x] = float(std::min(1.0, avg));
    }
    for (int z = 0; z < kBlendSize; ++z) {
      const float zz = grid_value(z, kBlendSize, 1e-4f, 0.99f);
      const float f0 = zz * zz * zz * zz, eta = ior_from_f0(f0);
      const auto blend_of = [&](float cos_oh) {
        return std::clamp((fresnel_dielectric(cos_oh, eta) - f0) / (1 - f0), 0.0f, 1.0f);
      };
      for (int y = 0; y < kBlendSize; ++y)
        for (int x = 0; x < kBlendSize; ++x)
          blend[(z * kBlendSize + y) * kBlendSize + x] = float(std::clamp(
              visible_normal_mean(grid_value(x, kBlendSize, 1e-4f, 1), grid_value(y, kBlendSize, 1e-4f, 1), false,
                                  blend_of), 0.0, 1.0));
    }
  }
};

const Tables& tables() {
  static const Tables t;  // thread-safe one-time initialisation
  return t;
}

// Linear interpolation on an evenly spaced axis of `size` nodes over [0, 1].
struct Axis {
  int i0, i1;
  float t;
  Axis(float v, int size) {
    const float x = std::clamp(v, 0.0f, 1.0f) * float(size - 1);
    i0 = std::min(int(x), size - 1);
    i1 = std::min(i0 + 1, size - 1);
    t = x - float(i0);
  }
};

float lerp(float a, float b, float t) { return a + (b - a) * t; }

}  // namespace

float ggx_albedo(float roughness, float mu) {
  const auto& e = tables().e;
  const Axis x(roughness, kRoughnessSize), y(mu, kMuSize);
  auto at = [&](int xi, int yi) { return e[yi * kRoughnessSize + xi]; };
  return lerp(lerp(at(x.i0, y.i0), at(x.i1, y.i0), x.t), lerp(at(x.i0, y.i1), at(x.i1, y.i1), x.t), y.t);
}

float ggx_average_albedo(float roughness) {
  const auto& a = tables().e_avg;
  const Axis x(roughness, kRoughnessSize);
  return lerp(a[x.i0], a[x.i1], x.t);
}

float ggx_fresnel_blend(float roughness, float mu, float eta) {
  const auto& b = tables().blend;
  const float zv = std::sqrt(std::fabs((eta - 1) / (eta + 1)));
  const Axis x(roughness, kBlendSize), y(mu, kBlendSize), z(zv, kBlendSize);
  auto at = [&](int xi, int yi, int zi) { return b[(zi * kBlendSize + yi) * kBlendSize + xi]; };
  auto plane = [&](int zi) {
    return lerp(lerp(at(x.i0, y.i0, zi), at(x.i1, y.i0, zi), x.t), lerp(at(x.i0, y.i1, zi), at(x.i1, y.i1, zi), x.t),
                y.t);
  };
  return lerp(plane(z.i0), plane(z.i1), z.t);
}

float dielectric_average_fresnel(float eta) {
  constexpr int kSteps = 64;
  double sum = 0;
  for (int k = 0; k < kSteps; ++k) {
    const float mu = (float(k) + 0.5f) / float(kSteps);
    sum += 2.0 * mu * fresnel_dielectric(mu, eta) / kSteps;
  }
  return float(sum);
}

float multiscatter_factor(float roughness, float mu, float f_ss) {
  const float e = std::max(ggx_albedo(roughness, mu), 1e-4f), e_avg = ggx_average_albedo(roughness);
  const float f_ms = f_ss * e_avg / (1 - f_ss * (1 - e_avg));
  return 1 + f_ms * (1 - e) / e;
}

}  // namespace tempera::tracer

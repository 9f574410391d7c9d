#pragma once
// Sampling tools of the LPE tracer: orthonormal frames, disk, cosine and cone
// samples, the (0,2)-sequence of pixel positions, MIS weights and discrete
// distributions (for emissive triangles and environment maps).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "tempera/tracer/scene.hpp"

namespace tempera::tracer {

constexpr float kPi = 3.14159265358979f;

struct Frame {  // orthonormal basis around a unit normal
  Float3 t, b, n;
  explicit Frame(Float3 normal) : n(normal) {
    // Branch-free basis (Duff et al. 2017).
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float c = n.x * n.y * a;
    t = {1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
  }
  Float3 to_world(Float3 v) const { return t * v.x + b * v.y + n * v.z; }
  Float3 to_local(Float3 v) const { return {dot(v, t), dot(v, b), dot(v, n)}; }
};

// Uniform point on the unit disk (concentric map keeps strata compact).
inline std::array<float, 2> sample_disk(float u1, float u2) {
  const float a = 2 * u1 - 1, b = 2 * u2 - 1;
  if (a == 0 && b == 0) return {0, 0};
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) r = a, phi = kPi / 4 * (b / a);
  else r = b, phi = kPi / 2 - kPi / 4 * (a / b);
  return {r * std::cos(phi), r * std::sin(phi)};
}

inline Float3 sample_cosine(float u1, float u2) {
  const auto d = sample_disk(u1, u2);
  return {d[0], d[1], std::sqrt(std::fmax(0.0f, 1 - d[0] * d[0] - d[1] * d[1]))};
}

// Uniform direction in the cone of half-angle acos(cos_max) around +Z.
inline Float3 sample_cone(float u1, float u2, float cos_max) {
  const float cos_t = 1 - u1 * (1 - cos_max), sin_t = std::sqrt(std::fmax(0.0f, 1 - cos_t * cos_t));
  return {sin_t * std::cos(2 * kPi * u2), sin_t * std::sin(2 * kPi * u2), cos_t};
}

// Radical inverses of the first two Sobol dimensions: a (0,2)-sequence, so
// any power-of-two prefix of the samples stratifies the pixel.
inline float sobol_dim0(std::uint32_t i) {
  std::uint32_t r = 0;
  for (std::uint32_t v = 1u << 31; i; i >>= 1, v >>= 1)
    if (i & 1) r ^= v;
  return float(r >> 8) * (1.0f / 16777216.0f);
}
inline float sobol_dim1(std::uint32_t i) {
  std::uint32_t r = 0;
  for (std::uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1)
    if (i & 1) r ^= v;
  return float(r >> 8) * (1.0f / 16777216.0f);
}
inline float scrambled(float u, std::uint32_t scramble) {  // XOR scrambling keeps the (0,2) property
  return float((std::uint32_t(u * 16777216.0f) ^ (scramble >> 8)) & 0xFFFFFF) * (1.0f / 16777216.0f);
}

inline float power_heuristic(float a, float b) { return a * a / (a * a + b * b); }

// A discrete distribution over weights (sampling an index in proportion).
class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(const std::vector<double>& weights) {
    cdf_.reserve(weights.size());
    for (double w : weights) cdf_.push_back(total_ += std::max(w, 0.0));
    for (double& c : cdf_) c = total_ > 0 ? c / total_ : 0;
    weights_ = weights;
  }
  bool empty() const { return !(total_ > 0); }
  std::size_t size() const { return cdf_.size(); }
  double total() const { return total_; }
  // Index for u in [0, 1) and its probability.
  std::size_t sample(double u, float& probability) const {
    const std::size_t i =
        std::min(std::size_t(std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin()), cdf_.size() - 1);
    probability = this->probability(i);
    return i;
  }
  float probability(std::size_t i) const { return float(std::max(weights_[i], 0.0) / total_); }

 private:
  std::vector<double> cdf_, weights_;
  double total_ = 0;
};

}  // namespace tempera::tracer

#include "tempera/methods/rigid/quadratic_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tempera/engine/error.hpp"

namespace tempera {

std::array<double, 6> quadratic_monomials(Vec2 p) { return {p.x, p.y, p.x * p.x, p.y * p.y, p.x * p.y, 1.0}; }

Vec2 apply(const QuadraticMap& D, Vec2 p) {
  const auto m = quadratic_monomials(p);
  Vec2 out;
  for (int j = 0; j < 6; ++j) {
    out.x += D.at(0, j) * m[std::size_t(j)];
    out.y += D.at(1, j) * m[std::size_t(j)];
  }
  return out;
}

std::array<double, 4> jacobian(const QuadraticMap& D, Vec2 p) {
  std::array<double, 4> J{};
  for (int i = 0; i < 2; ++i) {
    J[std::size_t(2 * i)] = D.at(i, 0) + 2 * D.at(i, 2) * p.x + D.at(i, 4) * p.y;
    J[std::size_t(2 * i + 1)] = D.at(i, 1) + 2 * D.at(i, 3) * p.y + D.at(i, 4) * p.x;
  }
  return J;
}

double jacobian_det(const QuadraticMap& D, Vec2 p) {
  const auto J = jacobian(D, p);
  return J[0] * J[3] - J[1] * J[2];
}

double polar_angle(const QuadraticMap& D) { return std::atan2(D.at(1, 0) - D.at(0, 1), D.at(0, 0) + D.at(1, 1)); }

QuadraticMap rotated(const QuadraticMap& D, double alpha) {
  const double c = std::cos(alpha), s = std::sin(alpha);
  QuadraticMap out = D;
  for (int j = 0; j < 6; ++j) {
    out.at(0, j) = c * D.at(0, j) - s * D.at(1, j);
    out.at(1, j) = s * D.at(0, j) + c * D.at(1, j);
  }
  return out;
}

namespace {

using Mat2 = std::array<double, 4>;  // row-major

Mat2 mul(const Mat2& a, const Mat2& b) {
  return {a[0] * b[0] + a[1] * b[2], a[0] * b[1] + a[1] * b[3], a[2] * b[0] + a[3] * b[2], a[2] * b[1] + a[3] * b[3]};
}
Mat2 transpose(const Mat2& a) { return {a[0], a[2], a[1], a[3]}; }
Mat2 inverse(const Mat2& a) {
  const double det = a[0] * a[3] - a[1] * a[2];
  if (std::abs(det) < 1e-12) throw ValueError("a change of frame must be invertible");
  return {a[3] / det, -a[1] / det, -a[2] / det, a[0] / det};
}

}  // namespace

QuadraticMap conjugated(const QuadraticMap& D, const std::array<double, 4>& L) {
  const Mat2 M = inverse(L);
  const Mat2 A{D.at(0, 0), D.at(0, 1), D.at(1, 0), D.at(1, 1)};
  const Mat2 A2 = mul(mul(L, A), M);
  // Component i's quadratic part is p^T H_i p with H_i symmetric.
  std::array<Mat2, 2> H;
  for (int i = 0; i < 2; ++i) {
    const Mat2 Hi{D.at(i, 2), D.at(i, 4) / 2, D.at(i, 4) / 2, D.at(i, 3)};
    H[std::size_t(i)] = mul(mul(transpose(M), Hi), M);
  }
  QuadraticMap out;
  for (int j = 0; j < 2; ++j) {
    Mat2 Hj{};
    for (int i = 0; i < 2; ++i)
      for (int k = 0; k < 4; ++k) Hj[std::size_t(k)] += L[std::size_t(2 * j + i)] * H[std::size_t(i)][std::size_t(k)];
    out.at(j, 0) = A2[std::size_t(2 * j)];
    out.at(j, 1) = A2[std::size_t(2 * j + 1)];
    out.at(j, 2) = Hj[0];
    out.at(j, 3) = Hj[3];
    out.at(j, 4) = Hj[1] + Hj[2];
    out.at(j, 5) = L[std::size_t(2 * j)] * D.at(0, 5) + L[std::size_t(2 * j + 1)] * D.at(1, 5);
  }
  return out;
}

double circular_mean(const std::vector<double>& angles, const std::vector<double>& weights) {
  if (angles.size() != weights.size()) throw ValueError("circular_mean: one weight per angle");
  double s = 0, c = 0;
  for (std::size_t k = 0; k < angles.size(); ++k) {
    s += weights[k] * std::sin(angles[k]);
    c += weights[k] * std::cos(angles[k]);
  }
  return std::atan2(s, c);
}

QuadraticMap blend(const std::vector<QuadraticMap>& maps, const std::vector<double>& weights) {
  if (maps.empty() || maps.size() != weights.size()) throw ValueError("blend: one weight per map, at least one map");
  std::vector<double> alphas;
  for (const auto& D : maps) alphas.push_back(polar_angle(D));
  QuadraticMap rotation_free;
  rotation_free.d.fill(0);
  for (std::size_t k = 0; k < maps.size(); ++k) {
    const QuadraticMap Dk = rotated(maps[k], -alphas[k]);
    for (std::size_t i = 0; i < 12; ++i) rotation_free.d[i] += weights[k] * Dk.d[i];
  }
  return rotated(rotation_free, circular_mean(alphas, weights));
}

QuadraticMap damped(const QuadraticMap& D, double xi) {
  QuadraticMap out;
  const QuadraticMap I = QuadraticMap::identity();
  for (std::size_t i = 0; i < 12; ++i) out.d[i] = xi * D.d[i] + (1 - xi) * I.d[i];
  return out;
}

Vec2 inverse_apply(const QuadraticMap& D, Vec2 q, bool* ok) {
  const Mat2 A{D.at(0, 0), D.at(0, 1), D.at(1, 0), D.at(1, 1)};
  const double det = A[0] * A[3] - A[1] * A[2];
  Vec2 p;
  if (std::abs(det) > 1e-12) {
    const double bx = q.x - D.at(0, 5), by = q.y - D.at(1, 5);
    p = {(A[3] * bx - A[1] * by) / det, (-A[2] * bx + A[0] * by) / det};
  }
  bool converged = false;
  for (int it = 0; it < 30; ++it) {
    const Vec2 r = apply(D, p);
    const double ex = r.x - q.x, ey = r.y - q.y;
    if (ex * ex + ey * ey < 1e-20) {
      converged = true;
      break;
    }
    const auto J = jacobian(D, p);
    const double dj = J[0] * J[3] - J[1] * J[2];
    if (std::abs(dj) < 1e-12) break;
    p.x -= (J[3] * ex - J[1] * ey) / dj;
    p.y -= (-J[2] * ex + J[0] * ey) / dj;
  }
  if (!converged) {
    const Vec2 r = apply(D, p);
    converged = std::hypot(r.x - q.x, r.y - q.y) < 1e-7;
  }
  if (ok) *ok = converged;
  return p;
}

double min_jacobian_det(const QuadraticMap& D, double extent) {
  // det J is quadratic in p, so its least value on the disc is at the centre,
  // a stationary point or the rim: 12 rings x 48 spokes resolve it.
  double least = jacobian_det(D, {0, 0});
  for (int ring = 1; ring <= 12; ++ring)
    for (int spoke = 0; spoke < 48; ++spoke) {
      const double r = extent * ring / 12, a = 2 * 3.14159265358979323846 * spoke / 48;
      least = std::min(least, jacobian_det(D, {r * std::cos(a), r * std::sin(a)}));
    }
  return least;
}

namespace {

QuadraticMap with_quadratic_scaled(const QuadraticMap& D, double s) {
  QuadraticMap out = D;
  for (int i = 0; i < 2; ++i)
    for (int j = 2; j <= 4; ++j) out.at(i, j) *= s;
  return out;
}

// Largest s in [0, 1] with min det J(make(s)) >= min_det, given make(0) passes.
template <class Make>
double largest_safe(const Make& make, double extent, double min_det) {
  double lo = 0, hi = 1;
  for (int it = 0; it < 30; ++it) {
    const double mid = (lo + hi) / 2;
    (min_jacobian_det(make(mid), extent) >= min_det ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace

QuadraticMap fold_guarded(const QuadraticMap& D, double extent, double min_det) {
  if (min_jacobian_det(D, extent) >= min_det) return D;
  const QuadraticMap affine = with_quadratic_scaled(D, 0);
  if (min_jacobian_det(affine, extent) >= min_det) {
    const auto make = [&](double s) { return with_quadratic_scaled(D, s); };
    return make(largest_safe(make, extent, min_det));
  }
  // The affine part folds too (a mirror or collapse): towards the identity.
  const auto make = [&](double s) { return damped(D, s); };
  return make(largest_safe(make, extent, min_det));
}

double distance_from_identity(const QuadraticMap& D) {
  const QuadraticMap I = QuadraticMap::identity();
  double s = 0;
  for (std::size_t i = 0; i < 12; ++i) s += (D.d[i] - I.d[i]) * (D.d[i] - I.d[i]);
  return std::sqrt(s);
}

}  // namespace tempera

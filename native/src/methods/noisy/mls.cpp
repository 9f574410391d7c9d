#include "tempera/methods/noisy/mls.hpp"

#include <algorithm>
#include <cmath>

#include "tempera/engine/error.hpp"
#include "tempera/engine/parallel.hpp"
#include "tempera/engine/patch_distance.hpp"
#include "tempera/engine/rng.hpp"

namespace tempera {

Point2 rigid_mls(const std::vector<Point2>& p, const std::vector<Point2>& q, Point2 v) {
  // f_r(v) = sum_i q^_i A_i with A_i = w_i [p^_i; -p^_i_perp] [v - p*; -(v - p*)_perp]^T
  // (Schaefer et al. 2006, eq. 6), then f(v) = |v - p*| f_r / |f_r| + q*.
  // Written out, f_r = (mu1 vx + mu2 vy, mu1 vy - mu2 vx) with
  // mu1 = sum w q^.p^ and mu2 = sum w (q^x p^y - q^y p^x), and both are
  // moments about the origin minus W q*.p*: one pass over the nodes, which
  // is what the per-frame warp of a 1 Mpix exemplar costs.
  double sw = 0, px = 0, py = 0, qx = 0, qy = 0, dot = 0, cross = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double dx = p[i].x - v.x, dy = p[i].y - v.y, d2 = dx * dx + dy * dy;
    if (d2 < 1e-12) return q[i];  // on a control point: its target exactly
    const double w = 1.0 / d2;
    sw += w, px += w * p[i].x, py += w * p[i].y, qx += w * q[i].x, qy += w * q[i].y;
    dot += w * (double(q[i].x) * p[i].x + double(q[i].y) * p[i].y);
    cross += w * (double(q[i].x) * p[i].y - double(q[i].y) * p[i].x);
  }
  px /= sw, py /= sw, qx /= sw, qy /= sw;
  const double mu1 = dot - sw * (qx * px + qy * py), mu2 = cross - sw * (qx * py - qy * px);
  const double vx = v.x - px, vy = v.y - py;
  const double fx = mu1 * vx + mu2 * vy, fy = mu1 * vy - mu2 * vx;
  const double len = std::sqrt(fx * fx + fy * fy), r = std::sqrt(vx * vx + vy * vy);
  if (len < 1e-12) return {float(qx), float(qy)};
  return {float(r * fx / len + qx), float(r * fy / len + qy)};
}

MlsLattice random_lattice(int width, int height, float spacing, float shift_min, float shift_max,
                          std::uint64_t seed) {
  if (!(spacing > 0) || shift_min < 0 || shift_max < shift_min)
    throw ValueError(concat("MLS lattice needs spacing > 0 and 0 <= shift min <= shift max, got ", spacing, ", ",
                            shift_min, ", ", shift_max));
  const int nx = std::max(2, int(std::lround(width / spacing)) + 1), ny = std::max(2, int(std::lround(height / spacing)) + 1);
  const float sx = float(width) / float(nx - 1), sy = float(height) / float(ny - 1);
  Rng rng(seed, 0x4D4C53ull);
  // Directions: one random heading for the frame plus a smooth random turn
  // per node, at most kMaxTurn between neighbours. With independent
  // directions two neighbours 50 px apart moving 25 px towards each other fold
  // the image; the paper's aim (features moved > 20 px between frames, the
  // medium intact) needs neighbours to move alike. Our choice: measured, it
  // keeps the Jacobian's singular values in [0.6, 1.6] (tests/cpp/test_noisy.cpp).
  constexpr float kMaxTurn = 0.5f;  // radians between neighbouring nodes
  const float heading = 6.28318531f * rng.uniform();
  std::vector<float> turn(std::size_t(nx) * ny), length(turn.size());
  for (std::size_t k = 0; k < turn.size(); ++k) {
    turn[k] = 2.0f * rng.uniform() - 1.0f;
    length[k] = shift_min + (shift_max - shift_min) * rng.uniform();
  }
  float max_step = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const float t = turn[std::size_t(j) * nx + i];
      if (i + 1 < nx) max_step = std::max(max_step, std::abs(t - turn[std::size_t(j) * nx + i + 1]));
      if (j + 1 < ny) max_step = std::max(max_step, std::abs(t - turn[std::size_t(j + 1) * nx + i]));
    }
  const float scale = max_step > kMaxTurn ? kMaxTurn / max_step : 1.0f;
  MlsLattice lattice;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::size_t k = std::size_t(j) * nx + i;
      const Point2 rest{i * sx - 0.5f, j * sy - 0.5f};
      const float angle = heading + scale * turn[k];
      lattice.rest.push_back(rest);
      lattice.moved.push_back({rest.x + length[k] * std::cos(angle), rest.y + length[k] * std::sin(angle)});
    }
  return lattice;
}

Image mls_backward_map(const MlsLattice& lattice, int width, int height) {
  Image map(width, height, 2);
  parallel_for(height, 0, [&](int y) {
    for (int x = 0; x < width; ++x) {
      const Point2 s = rigid_mls(lattice.moved, lattice.rest, {float(x), float(y)});
      map.at(x, y, 0) = s.x;
      map.at(x, y, 1) = s.y;
    }
  });
  return map;
}

Image warp_by_map(const ImageView& image, const ImageView& map, bool nearest) {
  if (map.channels != 2) throw ValueError("a warp map must have 2 channels (x, y)");
  Image out(map.width, map.height, image.channels);
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      const float sx = map.at(x, y, 0), sy = map.at(x, y, 1);
      if (nearest) {
        const int ix = std::clamp(int(std::lround(sx)), 0, image.width - 1);
        const int iy = std::clamp(int(std::lround(sy)), 0, image.height - 1);
        std::copy_n(image.pixel(ix, iy), image.channels, out.pixel(x, y));
      } else {
        sample_bilinear(image.data, image.width, image.height, image.channels, image.channels, sx, sy, out.pixel(x, y));
      }
    }
  return out;
}

}  // namespace tempera

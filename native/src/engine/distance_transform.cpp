#include "tempera/engine/distance_transform.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "tempera/engine/error.hpp"
#include "tempera/engine/parallel.hpp"

namespace tempera {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// 1D squared distance transform d(q) = min_p (q - p)² + f(p) (F&H, alg. 1):
// the lower envelope of the parabolas rooted at (p, f(p)). Infinite samples
// (no line in that column) are left out instead of being given a large
// finite value, which keeps the intersection arithmetic exact; if every
// sample is infinite, so is the result. `v` and `z` are scratch buffers;
// `arg`, if given, gets the minimizing p (-1 where d is infinite).
void squared_distance_1d(const double* f, double* d, int n, std::vector<int>& v, std::vector<double>& z,
                         int* arg = nullptr) {
  v.resize(n);
  z.resize(n + 1);
  int k = -1;  // index of the rightmost parabola in the envelope
  for (int q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;
    double s = -kInf;
    // Drop the parabolas that the new one hides.
    while (k >= 0) {
      const int p = v[k];
      s = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * (q - p));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -kInf : s;
    z[k + 1] = kInf;
  }
  if (k < 0) {
    std::fill_n(d, n, kInf);
    if (arg) std::fill_n(arg, n, -1);
    return;
  }
  for (int q = 0, j = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const double dq = q - v[j];
    d[q] = dq * dq + f[v[j]];
    if (arg) arg[q] = v[j];
  }
}

void check_mask(const ImageView& mask, std::string_view what) {
  require_nonempty(mask, what);
  if (mask.channels != 1) throw ValueError(concat(what, " must have 1 channel, got ", mask.channels));
  require_finite(mask, what);
}

}  // namespace

Image euclidean_distance(const ImageView& mask, std::string_view what) {
  check_mask(mask, what);
  const int w = mask.width, h = mask.height;
  // Squared distances, column pass then row pass (exact: the Euclidean
  // distance squared separates into the two axes).
  std::vector<double> sq(mask.pixel_count());
  for (std::size_t i = 0; i < sq.size(); ++i) sq[i] = mask.data[i] > 0.5f ? 0.0 : kInf;
  Image out(w, h, 1, std::numeric_limits<float>::infinity());
  if (std::find(sq.begin(), sq.end(), 0.0) == sq.end()) return out;
  parallel_for(w, 0, [&](int x) {
    std::vector<double> f(h), d(h), z;
    std::vector<int> v;
    for (int y = 0; y < h; ++y) f[y] = sq[std::size_t(y) * w + x];
    squared_distance_1d(f.data(), d.data(), h, v, z);
    for (int y = 0; y < h; ++y) sq[std::size_t(y) * w + x] = d[y];
  });
  parallel_for(h, 0, [&](int y) {
    std::vector<double> d(w), z;
    std::vector<int> v;
    squared_distance_1d(sq.data() + std::size_t(y) * w, d.data(), w, v, z);
    for (int x = 0; x < w; ++x) out.at(x, y, 0) = float(std::sqrt(d[x]));
  });
  return out;
}

Image nearest_mask_pixel(const ImageView& mask, std::string_view what) {
  check_mask(mask, what);
  const int w = mask.width, h = mask.height;
  std::vector<double> sq(mask.pixel_count());
  for (std::size_t i = 0; i < sq.size(); ++i) sq[i] = mask.data[i] > 0.5f ? 0.0 : kInf;
  Image out(w, h, 2, -1.0f);
  if (std::find(sq.begin(), sq.end(), 0.0) == sq.end()) return out;
  // The same two passes, keeping the argmin: per column the nearest mask
  // row, then per row the column whose (column distance, row distance) wins.
  std::vector<int> row_of(mask.pixel_count());
  parallel_for(w, 0, [&](int x) {
    std::vector<double> f(h), d(h), z;
    std::vector<int> v, arg(h);
    for (int y = 0; y < h; ++y) f[y] = sq[std::size_t(y) * w + x];
    squared_distance_1d(f.data(), d.data(), h, v, z, arg.data());
    for (int y = 0; y < h; ++y) sq[std::size_t(y) * w + x] = d[y], row_of[std::size_t(y) * w + x] = arg[y];
  });
  parallel_for(h, 0, [&](int y) {
    std::vector<double> d(w), z;
    std::vector<int> v, arg(w);
    squared_distance_1d(sq.data() + std::size_t(y) * w, d.data(), w, v, z, arg.data());
    for (int x = 0; x < w; ++x) {
      const int nx = arg[x];
      out.at(x, y, 0) = float(nx);
      out.at(x, y, 1) = float(row_of[std::size_t(y) * w + nx]);
    }
  });
  return out;
}

Image line_distance(const ImageView& mask, float d_max) {
  require_nonempty(mask, "line mask");
  if (!(d_max > 0.0f) || !std::isfinite(d_max))
    throw ValueError(concat("d_max must be a positive finite number, got ", d_max));
  Image out = euclidean_distance(mask, "line mask");
  for (std::size_t i = 0; i < out.pixel_count(); ++i) out.data()[i] = std::min(out.data()[i], d_max) / d_max;
  return out;
}

}  // namespace tempera

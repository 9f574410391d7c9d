#include "tempera/methods/rigid/quadratic_fit.hpp"

#include <algorithm>
#include <cmath>

#include "tempera/engine/distance_transform.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/methods/rigid/silhouette.hpp"

namespace tempera {

namespace {

struct Moments {
  Vec2 mean;
  std::array<double, 3> cov{};  // xx, xy, yy
};

Moments moments(const ImageView& weights, ObjectFrame frame) {
  double s = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  for (int y = 0; y < weights.height; ++y)
    for (int x = 0; x < weights.width; ++x) {
      const double w = weights.at(x, y, 0);
      if (w <= 0) continue;
      const double u = (x - frame.centre.x) / frame.radius, v = (y - frame.centre.y) / frame.radius;
      s += w, sx += w * u, sy += w * v, sxx += w * u * u, sxy += w * u * v, syy += w * v * v;
    }
  if (s <= 0) throw ValueError("an empty silhouette cannot be registered");
  Moments m;
  m.mean = {sx / s, sy / s};
  m.cov = {sxx / s - m.mean.x * m.mean.x, sxy / s - m.mean.x * m.mean.y, syy / s - m.mean.y * m.mean.y};
  return m;
}

using Mat2 = std::array<double, 4>;

// Square root of a symmetric positive definite 2 x 2 matrix (xx, xy, yy).
Mat2 sqrt_spd(const std::array<double, 3>& c) {
  const double det = std::max(c[0] * c[2] - c[1] * c[1], 1e-18);
  const double s = std::sqrt(det), t = std::sqrt(std::max(c[0] + c[2] + 2 * s, 1e-18));
  return {(c[0] + s) / t, c[1] / t, c[1] / t, (c[2] + s) / t};
}

Mat2 mul(const Mat2& a, const Mat2& b) {
  return {a[0] * b[0] + a[1] * b[2], a[0] * b[1] + a[1] * b[3], a[2] * b[0] + a[3] * b[2], a[2] * b[1] + a[3] * b[3]};
}

Mat2 inverse(const Mat2& a) {
  const double det = a[0] * a[3] - a[1] * a[2];
  return {a[3] / det, -a[1] / det, -a[2] / det, a[0] / det};
}

// A value image with its central-difference gradient, 3 channels
// (value, d/dx, d/dy), sampled bilinearly in one go.
struct Sample {
  double value, gx, gy;
};

Image with_gradient(const Image& img) {
  const int w = img.width(), h = img.height();
  Image out(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* o = out.pixel(x, y);
      o[0] = img.at(x, y, 0);
      o[1] = 0.5f * (img.at(std::min(x + 1, w - 1), y, 0) - img.at(std::max(x - 1, 0), y, 0));
      o[2] = 0.5f * (img.at(x, std::min(y + 1, h - 1), 0) - img.at(x, std::max(y - 1, 0), 0));
    }
  return out;
}

Sample sample(const Image& img, double x, double y) {
  x = std::clamp(x, 0.0, img.width() - 1.0);
  y = std::clamp(y, 0.0, img.height() - 1.0);
  const int x0 = std::min(int(x), std::max(0, img.width() - 2)), y0 = std::min(int(y), std::max(0, img.height() - 2));
  const int x1 = std::min(x0 + 1, img.width() - 1), y1 = std::min(y0 + 1, img.height() - 1);
  const double fx = x - x0, fy = y - y0;
  const float *a = img.pixel(x0, y0), *b = img.pixel(x1, y0), *c = img.pixel(x0, y1), *d = img.pixel(x1, y1);
  double v[3];
  for (int k = 0; k < 3; ++k) v[k] = (1 - fy) * ((1 - fx) * a[k] + fx * b[k]) + fy * ((1 - fx) * c[k] + fx * d[k]);
  return {v[0], v[1], v[2]};
}

// Gauss-Newton normal equations of the 12 parameters.
struct Normal {
  std::array<double, 144> H{};
  std::array<double, 12> g{};
  double energy = 0;

  void add(const std::array<double, 12>& J, double r, double weight) {
    for (int a = 0; a < 12; ++a) {
      if (J[std::size_t(a)] == 0) continue;
      g[std::size_t(a)] += weight * J[std::size_t(a)] * r;
      for (int b = a; b < 12; ++b) H[std::size_t(a * 12 + b)] += weight * J[std::size_t(a)] * J[std::size_t(b)];
    }
    energy += weight * r * r;
  }
};

// Solves H x = -g by Gaussian elimination with partial pivoting.
std::array<double, 12> solve(std::array<double, 144> H, std::array<double, 12> g) {
  for (int a = 0; a < 12; ++a)
    for (int b = 0; b < a; ++b) H[std::size_t(a * 12 + b)] = H[std::size_t(b * 12 + a)];  // add() fills the upper half
  std::array<double, 12> x{};
  for (double& v : g) v = -v;
  for (int c = 0; c < 12; ++c) {
    int p = c;
    for (int r = c + 1; r < 12; ++r)
      if (std::abs(H[std::size_t(r * 12 + c)]) > std::abs(H[std::size_t(p * 12 + c)])) p = r;
    if (std::abs(H[std::size_t(p * 12 + c)]) < 1e-300) return x;
    for (int k = 0; k < 12; ++k) std::swap(H[std::size_t(c * 12 + k)], H[std::size_t(p * 12 + k)]);
    std::swap(g[std::size_t(c)], g[std::size_t(p)]);
    for (int r = c + 1; r < 12; ++r) {
      const double f = H[std::size_t(r * 12 + c)] / H[std::size_t(c * 12 + c)];
      for (int k = c; k < 12; ++k) H[std::size_t(r * 12 + k)] -= f * H[std::size_t(c * 12 + k)];
      g[std::size_t(r)] -= f * g[std::size_t(c)];
    }
  }
  for (int r = 11; r >= 0; --r) {
    double s = g[std::size_t(r)];
    for (int k = r + 1; k < 12; ++k) s -= H[std::size_t(r * 12 + k)] * x[std::size_t(k)];
    x[std::size_t(r)] = s / H[std::size_t(r * 12 + r)];
  }
  return x;
}

bool is_quadratic_entry(int index) { return index % 6 >= 2 && index % 6 <= 4; }

// One coarse-to-fine stage's data and energy.
struct Stage {
  ObjectFrame frame;
  Image drawn, distance;  // blurred drawn silhouette; stroke distance (px)
  std::vector<Vec2> pixels;
  std::vector<double> targets;  // blurred source silhouette at `pixels`
  std::vector<Vec2> outline;    // the proxy's outline (px)
  double silhouette_weight = 1, chamfer_weight = 0, prior = 0, sigma = 1;

  // The energy alone (trial steps), or with its normal equations.
  double energy(const QuadraticMap& D) const { return evaluate(D, false).energy; }
  Normal normal_equations(const QuadraticMap& D) const { return evaluate(D, true); }

  Normal evaluate(const QuadraticMap& D, bool with_normal) const {
    Normal n;
    std::array<double, 12> J{};
    // d(sample at frame(D(u))) / dD_ij = radius * gradient_i * monomial_j(u).
    const auto jac = [&](Vec2 u, Sample s) {
      const auto m = quadratic_monomials(u);
      for (int j = 0; j < 6; ++j) {
        J[std::size_t(j)] = frame.radius * s.gx * m[std::size_t(j)];
        J[std::size_t(6 + j)] = frame.radius * s.gy * m[std::size_t(j)];
      }
    };
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      const Vec2 u{(pixels[i].x - frame.centre.x) / frame.radius, (pixels[i].y - frame.centre.y) / frame.radius};
      const Vec2 q = apply(D, u);
      const Sample s = sample(drawn, frame.centre.x + frame.radius * q.x, frame.centre.y + frame.radius * q.y);
      const double r = s.value - targets[i];
      if (with_normal) jac(u, s), n.add(J, r, silhouette_weight);
      else n.energy += silhouette_weight * r * r;
    }
    for (const Vec2& b : outline) {
      const Vec2 u{(b.x - frame.centre.x) / frame.radius, (b.y - frame.centre.y) / frame.radius};
      const Vec2 q = apply(D, u);
      Sample s = sample(distance, frame.centre.x + frame.radius * q.x, frame.centre.y + frame.radius * q.y);
      s = {s.value / sigma, s.gx / sigma, s.gy / sigma};
      if (with_normal) jac(u, s), n.add(J, s.value, chamfer_weight);
      else n.energy += chamfer_weight * s.value * s.value;
    }
    for (int a = 0; a < 12; ++a)
      if (is_quadratic_entry(a)) {
        if (with_normal) n.H[std::size_t(a * 13)] += prior;
        n.g[std::size_t(a)] += prior * D.d[std::size_t(a)];
        n.energy += prior * D.d[std::size_t(a)] * D.d[std::size_t(a)];
      }
    return n;
  }
};

Stage make_stage(const ImageView& source_mask, const Image& drawn_silhouette, const ImageView& drawn_ink,
                 ObjectFrame frame, float sigma, const QuadraticFitOptions& options) {
  Stage st;
  st.frame = frame;
  st.sigma = std::max(1.0, double(sigma));
  st.drawn = with_gradient(gaussian_blur(drawn_silhouette.view(), sigma));
  const Image source = gaussian_blur(source_mask, sigma);
  const int stride = std::max(1, int(sigma / 2));
  for (int y = 0; y < source.height(); y += stride)
    for (int x = 0; x < source.width(); x += stride) {
      const float v = source.at(x, y, 0);
      if (v > 0.01f && v < 0.99f) st.pixels.push_back({double(x), double(y)}), st.targets.push_back(v);
    }
  if (st.pixels.empty()) throw ValueError("the source silhouette is empty");
  if (options.chamfer_weight > 0) {
    const float d_max = 4 * float(st.sigma);
    st.distance = line_distance(drawn_ink, d_max);
    for (std::size_t i = 0; i < st.distance.pixel_count(); ++i) st.distance.data()[i] *= d_max;
    st.distance = with_gradient(st.distance);
    const std::vector<Vec2> all = iso_points(source_mask, 0.5f);
    const std::size_t step = std::max<std::size_t>(1, all.size() / 600);
    for (std::size_t i = 0; i < all.size(); i += step) st.outline.push_back(all[i]);
  }
  // Both terms per sample, so that their balance does not depend on size.
  st.silhouette_weight = 1.0 / double(st.pixels.size());
  st.chamfer_weight = st.outline.empty() ? 0 : options.chamfer_weight / double(st.outline.size());
  st.prior = options.prior;
  return st;
}

// The fill closed a region: more filled than inked pixels.
bool outline_is_closed(const ImageView& silhouette, const ImageView& ink) {
  std::size_t filled = 0, inked = 0;
  for (std::size_t i = 0; i < ink.pixel_count(); ++i) filled += silhouette.data[i] > 0.75f, inked += ink.data[i] > 0.5f;
  return filled > inked;
}

// A thin band along the mask's boundary, the outline's counterpart to ink.
Image outline_band(const ImageView& mask) {
  Image band(mask.width, mask.height, 1);
  for (std::size_t i = 0; i < mask.pixel_count(); ++i) band.data()[i] = 4 * mask.data[i] * (1 - mask.data[i]);
  return gaussian_blur(band.view(), 1.0f);
}

}  // namespace

QuadraticMap moment_affine(const ImageView& source_silhouette, const ImageView& drawn_silhouette, ObjectFrame frame) {
  const Moments s = moments(source_silhouette, frame), e = moments(drawn_silhouette, frame);
  const Mat2 A = mul(sqrt_spd(e.cov), inverse(sqrt_spd(s.cov)));
  QuadraticMap D;
  D.at(0, 0) = A[0], D.at(0, 1) = A[1], D.at(1, 0) = A[2], D.at(1, 1) = A[3];
  D.at(0, 5) = e.mean.x - (A[0] * s.mean.x + A[1] * s.mean.y);
  D.at(1, 5) = e.mean.y - (A[2] * s.mean.x + A[3] * s.mean.y);
  return D;
}

QuadraticMap fit_quadratic_map(const ImageView& source_mask, const ImageView& drawn_ink, ObjectFrame frame,
                               const QuadraticFitOptions& options) {
  require_nonempty(source_mask, "source mask");
  require_nonempty(drawn_ink, "drawing");
  require_same_size(source_mask, "source mask", drawn_ink, "drawing");
  if (source_mask.channels != 1 || drawn_ink.channels != 1)
    throw ValueError("the source mask and the drawing must have 1 channel each");
  if (!(frame.radius > 0)) throw ValueError("the object's radius must be positive");
  validate_fields(options, quadratic_fit_option_table());
  if (options.blurs.empty()) throw ValueError("fit_blurs needs at least one stage");
  const Image drawn_silhouette = filled_silhouette(drawn_ink);
  const bool closed = outline_is_closed(drawn_silhouette.view(), drawn_ink);
  if (!closed && options.chamfer_weight <= 0)
    throw ValueError("the drawn outline is not closed (its fill leaks out) and the chamfer term is off");
  // A leaking fill has no region to match: outline against outline instead.
  QuadraticMap D = closed ? moment_affine(source_mask, drawn_silhouette.view(), frame)
                          : moment_affine(outline_band(source_mask).view(), drawn_ink, frame);
  for (const float sigma : options.blurs) {
    Stage stage = make_stage(source_mask, drawn_silhouette, drawn_ink, frame, sigma, options);
    if (!closed) stage.silhouette_weight = 0;
    Normal n = stage.normal_equations(D);
    for (int it = 0; it < options.iterations; ++it) {
      const std::array<double, 12> step = solve(n.H, n.g);
      double t = 1;
      bool improved = false;
      for (int halving = 0; halving < 6 && !improved; ++halving, t /= 2) {
        QuadraticMap trial = D;
        for (std::size_t i = 0; i < 12; ++i) trial.d[i] += t * step[i];
        if (stage.energy(trial) < n.energy) D = trial, n = stage.normal_equations(D), improved = true;
      }
      double largest = 0;
      for (double s : step) largest = std::max(largest, std::abs(s));
      if (!improved || largest < 1e-6) break;
    }
  }
  return D;
}

}  // namespace tempera

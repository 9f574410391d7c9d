#pragma once
// The quadratic deformation of Müller et al. 2005 as Dvorožňák et al. 2017
// use it (eq. 1-2): p' = D (x, y, x^2, y^2, xy, 1)^T with D = [A | Q | m | t]
// (2 x 6, 12 parameters). Coordinates are centroid-relative and divided by
// the proxy radius r (design choice, docs/rigid_bodies.md): then rotating,
// blending and scaling D mean the same thing for every object size.
#include <array>
#include <vector>

namespace tempera {

struct Vec2 {
  double x = 0, y = 0;
};

// Row i holds (a_i1, a_i2, q_i1, q_i2, m_i, t_i), the paper's order.
struct QuadraticMap {
  std::array<double, 12> d{1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0};

  static QuadraticMap identity() { return {}; }
  double& at(int row, int col) { return d[std::size_t(row * 6 + col)]; }
  double at(int row, int col) const { return d[std::size_t(row * 6 + col)]; }
};

// The six monomials (x, y, x^2, y^2, xy, 1).
std::array<double, 6> quadratic_monomials(Vec2 p);
Vec2 apply(const QuadraticMap& D, Vec2 p);
// The Jacobian dD/dp at p, row-major (j00, j01, j10, j11).
std::array<double, 4> jacobian(const QuadraticMap& D, Vec2 p);
double jacobian_det(const QuadraticMap& D, Vec2 p);

// Rotation angle of the polar decomposition A = R_alpha U (U symmetric
// positive definite): alpha = atan2(a21 - a12, a11 + a22), closed form in 2D.
// (The paper writes arctan(r11 / r21), a misprint for atan2(r21, r11).)
double polar_angle(const QuadraticMap& D);
// R_alpha D: every output rotated by alpha.
QuadraticMap rotated(const QuadraticMap& D, double alpha);
// The map seen through a linear change of frame L (2 x 2, row-major):
// D_L(p) = L D(L^-1 p), again quadratic and in closed form. With L a
// rotation or a flip this carries a drawn deformation to a rotated or
// mirrored motion (the augmentation).
QuadraticMap conjugated(const QuadraticMap& D, const std::array<double, 4>& L);

// Weighted circular mean of angles: atan2(sum w sin, sum w cos).
double circular_mean(const std::vector<double>& angles, const std::vector<double>& weights);
// Rotation-aware blend (eq. 7-9): alpha_hat = circular mean of the polar
// angles, D_hat' = sum w_k R_{-alpha_k} D_k, D_hat = R_alpha_hat D_hat'.
QuadraticMap blend(const std::vector<QuadraticMap>& maps, const std::vector<double>& weights);
// Damping (eq. 10): xi D + (1 - xi) I.
QuadraticMap damped(const QuadraticMap& D, double xi);

// D^-1(q) by Newton steps from the affine inverse; `ok` false when Newton
// did not converge (q outside D's image, or a fold).
Vec2 inverse_apply(const QuadraticMap& D, Vec2 q, bool* ok = nullptr);

// Least det J of D over the disc |p| <= extent (radius units).
double min_jacobian_det(const QuadraticMap& D, double extent);
// The fold guard: D unchanged when det J >= min_det over the disc of radius
// `extent` (every proxy lies in the unit disc; 1.25 leaves room for the
// strokes); otherwise
// its quadratic part (Q, m) is scaled down by the largest factor s in [0, 1]
// that keeps det J >= min_det (bisection), and if the affine part itself is
// folded, the whole map is blended towards the identity.
QuadraticMap fold_guarded(const QuadraticMap& D, double extent = 1.25, double min_det = 0.05);

// Frobenius norm of D - I: how far a frame is from rigid.
double distance_from_identity(const QuadraticMap& D);

}  // namespace tempera

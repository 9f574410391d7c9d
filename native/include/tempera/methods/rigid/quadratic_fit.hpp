#pragma once
// Registration of a drawn frame f^e to its source frame f^s by one quadratic
// map D (Dvorožňák et al. 2017, §5.1). The paper uses Sýkora et al. 2009's
// as-rigid-as-possible registration; here (design choice, docs/rigid_bodies.md)
// a Gauss-Newton Lucas-Kanade with the quadratic warp on blurred filled
// silhouettes, coarse to fine, plus a chamfer term pulling the source's
// outline onto the drawn strokes' distance transform, and a small prior on
// the quadratic part. It starts from the moment-matched affine map.
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/methods/rigid/quadratic_map.hpp"

namespace tempera {

// Where an object is in a frame: D acts on (p - centre) / radius.
struct ObjectFrame {
  Vec2 centre;        // px
  double radius = 1;  // px, the proxy's radius
};

struct QuadraticFitOptions {
  std::vector<float> blurs{8, 4, 2};  // Gaussian sigma (px) of each coarse-to-fine stage
  int iterations = 25;                // Gauss-Newton steps per stage
  float chamfer_weight = 0.5f;        // weight of the outline-to-stroke chamfer term
  float prior = 0.02f;                // mu in mu |[Q m]|^2
};

inline const auto& quadratic_fit_option_table() {
  using F = QuadraticFitOptions;
  static const auto table = std::make_tuple(
      field(&F::blurs, "fit_blurs", "fit-blurs",
            "Gaussian blurs (px) of the coarse-to-fine registration stages, coarsest first (8,4,2)", 0, 256),
      field(&F::iterations, "fit_iterations", "fit-iterations", "Gauss-Newton steps per registration stage (25)", 1, 1000),
      field(&F::chamfer_weight, "fit_chamfer", "fit-chamfer",
            "weight of the chamfer term pulling the proxy's outline onto the drawn strokes (0.5; 0 = silhouettes only)",
            0, 1e6),
      field(&F::prior, "fit_prior", "fit-prior", "prior mu |[Q m]|^2 against needless bending (0.02)", 0, 1e6));
  return table;
}

// Moment-matched affine map from the source silhouette to the drawn one
// (both 1 channel, same size): centroids and covariances matched with
// symmetric square roots, so no rotation is guessed.
QuadraticMap moment_affine(const ImageView& source_silhouette, const ImageView& drawn_silhouette, ObjectFrame frame);

// D with f^e(frame(D(u))) ~ f^s(frame(u)). `source_mask` is the proxy's
// filled coverage, `drawn_ink` the drawing's ink coverage (both 1 channel,
// same size).
QuadraticMap fit_quadratic_map(const ImageView& source_mask, const ImageView& drawn_ink, ObjectFrame frame,
                               const QuadraticFitOptions& options = {});

}  // namespace tempera

#pragma once
// Principal-component compression of the guide channels (StyLit's preview
// mode compresses the LPE channels with PCA, thesis §8.3.4). Guides are first
// scaled by the square roots of their weights, so squared distances between
// projected pixels equal the weighted guide distances up to the variance left
// out. Light-path buffers are strongly correlated (RGB of similar lighting),
// so a handful of components keep almost all of it and halve the work of
// every patch comparison.
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

// The guide layers of one image as the caller gave them, read as if stacked:
// their channels side by side, each layer scaled by the square root of its
// weight. The projection reads them in place, so the stacked copy (12
// channels of floats for four RGB light-path buffers, twice the projected
// guides) never exists.
struct WeightedGuides {
  std::vector<ImageView> layers;  // all of one size
  std::vector<float> scales;      // one per layer

  int channels() const;
  std::size_t pixel_count() const { return layers.empty() ? 0 : layers.front().pixel_count(); }
  // The stacked, scaled channels of pixel i (channels() values).
  void pixel(std::size_t i, float* out) const;
  // All pixels so: the stack itself, for guides matched uncompressed.
  Image stacked() const;
};

struct GuideProjection {
  int input_channels = 0;
  std::vector<float> mean;        // input_channels
  std::vector<float> components;  // rows of input_channels, one per kept component
  double kept_variance = 1.0;     // fraction of the weighted variance kept

  int output_channels() const { return input_channels ? int(components.size()) / input_channels : 0; }
  Image apply(const WeightedGuides& guides) const;
};

// Fitted on the weighted guides of every source (read as one image, their
// rows one after another) and of the target (same channel count). Keeps the
// fewest leading components whose variance reaches `keep` of the total (at
// least one).
GuideProjection fit_guide_projection(const std::vector<WeightedGuides>& sources, const WeightedGuides& target,
                                     double keep);

// Eigen-decomposition of a symmetric n x n matrix (row-major) by cyclic Jacobi
// rotations: eigenvalues descending, eigenvectors as rows.
void symmetric_eigen(std::vector<double> matrix, int n, std::vector<double>& values, std::vector<double>& vectors);

}  // namespace tempera

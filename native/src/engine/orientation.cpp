#include "tempera/engine/orientation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "tempera/engine/error.hpp"
#include "tempera/engine/parallel.hpp"

namespace tempera {

namespace {

// Luminance stand-in: mean of R, G, B; a 1- or 2-channel image (gray, or
// gray + alpha) uses its first channel.
Image grayscale(const ImageView& img) {
  const int n = img.channels >= 3 ? 3 : 1;
  Image out(img.width, img.height, 1);
  parallel_for(img.height, 0, [&](int y) {
    for (int x = 0; x < img.width; ++x) {
      const float* p = img.pixel(x, y);
      float sum = 0.0f;
      for (int k = 0; k < n; ++k) sum += p[k];
      out.at(x, y, 0) = sum / float(n);
    }
  });
  return out;
}

// The Gaussian's taps out to 3 sigma, clamped to `limit` (the image's extent
// along the axis minus one): with the border replicated, every tap beyond it
// reads the edge pixel for every output pixel, so folding its weight into the
// outermost tap gives exactly the unclamped blur at a bounded cost.
std::vector<float> gaussian_kernel(float sigma, int limit) {
  const long full = long(std::ceil(3.0 * double(sigma)));  // sigma <= kMaxSigma: no overflow
  const int radius = int(std::min<long>(full, std::max(limit, 0)));
  std::vector<double> k(2 * std::size_t(radius) + 1, 0.0);
  double sum = 0.0;
  for (long i = -full; i <= full; ++i) {
    const double w = std::exp(-0.5 * double(i) * double(i) / (double(sigma) * sigma));
    k[std::size_t(std::clamp<long>(i, -radius, radius) + radius)] += w;
    sum += w;
  }
  std::vector<float> out(k.size());
  for (std::size_t i = 0; i < k.size(); ++i) out[i] = float(k[i] / sum);
  return out;
}

// Separable Gaussian blur of all channels in place, replicating the border.
// Both passes add whole shifted rows, so the inner loops are contiguous.
void gaussian_blur(Image& img, float sigma) {
  if (sigma <= 0.0f) return;
  const int w = img.width(), h = img.height(), c = img.channels();
  const std::vector<float> kx = gaussian_kernel(sigma, w - 1), ky = gaussian_kernel(sigma, h - 1);
  const int rx = int(kx.size() / 2), ry = int(ky.size() / 2);
  const std::size_t row = std::size_t(w) * c;
  Image tmp(w, h, c);
  parallel_for(h, 0, [&](int y) {  // horizontal: img -> tmp, via a row padded with its edge pixels
    std::vector<float> padded((std::size_t(w) + 2 * rx) * c);
    for (int x = -rx; x < w + rx; ++x)
      std::copy_n(img.pixel(std::clamp(x, 0, w - 1), y), c, &padded[std::size_t(x + rx) * c]);
    float* out = tmp.pixel(0, y);
    for (int i = 0; i <= 2 * rx; ++i) {
      const float* in = padded.data() + std::size_t(i) * c;
      for (std::size_t j = 0; j < row; ++j) out[j] += kx[i] * in[j];
    }
  });
  parallel_for(h, 0, [&](int y) {  // vertical: tmp -> img
    float* out = img.pixel(0, y);
    std::fill_n(out, row, 0.0f);
    for (int i = -ry; i <= ry; ++i) {
      const float* in = tmp.pixel(0, std::clamp(y + i, 0, h - 1));
      for (std::size_t j = 0; j < row; ++j) out[j] += ky[i + ry] * in[j];
    }
  });
}

}  // namespace

StructureTensorField structure_tensor(const ImageView& gray, float sigma) {
  require_nonempty(gray, "image");
  require_finite(gray, "image");
  if (!(sigma >= 0.0f) || !(sigma <= kMaxStructureTensorSigma))
    throw ValueError(concat("structure tensor sigma must be from 0 to ", kMaxStructureTensorSigma,
                            " pixels, got ", sigma));
  const Image g = grayscale(gray);
  const int w = g.width(), h = g.height();
  Image tensor(w, h, 3);
  parallel_for(h, 0, [&](int y) {
    const int ym = std::max(y - 1, 0), yp = std::min(y + 1, h - 1);
    for (int x = 0; x < w; ++x) {
      const int xm = std::max(x - 1, 0), xp = std::min(x + 1, w - 1);
      auto I = [&](int xx, int yy) { return g.at(xx, yy, 0); };
      // Sobel, scaled by 1/8 so that a unit ramp has a unit gradient; more
      // isotropic than plain central differences for the angle.
      const float gx = (I(xp, ym) - I(xm, ym) + 2.0f * (I(xp, y) - I(xm, y)) + I(xp, yp) - I(xm, yp)) / 8.0f;
      const float gy = (I(xm, yp) - I(xm, ym) + 2.0f * (I(x, yp) - I(x, ym)) + I(xp, yp) - I(xp, ym)) / 8.0f;
      float* t = tensor.pixel(x, y);
      t[0] = gx * gx;
      t[1] = gx * gy;
      t[2] = gy * gy;
    }
  });
  gaussian_blur(tensor, sigma);
  return tensor;
}

Image orientation_from_tensor(const ImageView& tensor) {
  require_nonempty(tensor, "structure tensor");
  if (tensor.channels != 3)
    throw ValueError(concat("structure tensor must have 3 channels (Jxx, Jxy, Jyy), got ", tensor.channels));
  require_finite(tensor, "structure tensor");
  constexpr double pi = std::numbers::pi;
  Image out(tensor.width, tensor.height, 2);
  parallel_for(tensor.height, 0, [&](int y) {
    for (int x = 0; x < tensor.width; ++x) {
      const float* t = tensor.pixel(x, y);
      const double jxx = t[0], jxy = t[1], jyy = t[2];
      // Eigenvector of the larger eigenvalue = gradient direction; the edge
      // runs perpendicular to it.
      const double angle = 0.5 * std::atan2(2.0 * jxy, jxx - jyy) + 0.5 * pi;  // in [0, π]
      float a = float(angle);
      if (a >= float(pi)) a = 0.0f;  // [0, π) even after rounding to float
      const double trace = jxx + jyy, diff = std::sqrt((jxx - jyy) * (jxx - jyy) + 4.0 * jxy * jxy);
      out.at(x, y, 0) = a;
      out.at(x, y, 1) = trace > 0.0 ? float(std::clamp(diff / trace, 0.0, 1.0)) : 0.0f;
    }
  });
  return out;
}

}  // namespace tempera

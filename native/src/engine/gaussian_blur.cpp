#include "tempera/engine/gaussian_blur.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tempera {

namespace {

// Normalised taps exp(-i²/2σ²) for i in [-radius, radius].
std::vector<float> gaussian_kernel(float sigma, int radius) {
  std::vector<float> kernel(std::size_t(2 * radius + 1));
  float sum = 0;
  for (int i = -radius; i <= radius; ++i)
    sum += kernel[std::size_t(i + radius)] = std::exp(-0.5f * float(i * i) / (sigma * sigma));
  for (float& k : kernel) k /= sum;
  return kernel;
}

// One 1-D pass along x or y, edges clamped.
Image blur_pass(const ImageView& image, const std::vector<float>& kernel, bool along_x) {
  const int w = image.width, h = image.height, c = image.channels;
  const int radius = int(kernel.size() / 2);
  Image out(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* o = out.pixel(x, y);
      for (int i = -radius; i <= radius; ++i) {
        const float k = kernel[std::size_t(i + radius)];
        const float* p = along_x ? image.pixel(std::clamp(x + i, 0, w - 1), y)
                                 : image.pixel(x, std::clamp(y + i, 0, h - 1));
        for (int ch = 0; ch < c; ++ch) o[ch] += k * p[ch];
      }
    }
  return out;
}

}  // namespace

Image gaussian_blur(const ImageView& image, float sigma) {
  require_nonempty(image, "image to blur");
  if (sigma <= 0) return Image::copy_of(image);
  const std::vector<float> kernel = gaussian_kernel(sigma, int(std::ceil(3 * sigma)));
  const Image rows = blur_pass(image, kernel, true);
  return blur_pass(rows.view(), kernel, false);
}

}  // namespace tempera

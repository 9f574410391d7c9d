#pragma once
// Shared by the TCIA tests: their small solver settings, a smooth random
// texture and the measures of the in-betweens against ground truth (SSIM,
// gradient energy).
#include <algorithm>
#include <random>

#include "tempera/engine/image.hpp"
#include "tempera/methods/tcia/tcia.hpp"

namespace tempera::test {

// The method's defaults on 2 threads, few levels and 7 x 7 patches: small shots, fast.
inline TciaOptions fast_options(int levels = 3) {
  TciaOptions o = default_tcia_options();
  o.synthesis.threads = 2;
  o.synthesis.levels = levels;
  o.synthesis.patch_size = 7;
  return o;
}

// Uniform noise blurred by a 3 x 3 box.
inline Image smooth_noise(int w, int h, int c, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Image img(w, h, c);
  for (std::size_t i = 0; i < img.pixel_count() * c; ++i) img.data()[i] = u(rng);
  Image out(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) {
        float s = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) s += img.at(std::clamp(x + dx, 0, w - 1), std::clamp(y + dy, 0, h - 1), k);
        out.at(x, y, k) = s / 9;
      }
  return out;
}

// Mean SSIM of the luminance over 8 x 8 windows, 4 px apart (Wang et al. 2004's constants).
inline double ssim(const Image& a, const Image& b) {
  auto lum = [](const Image& im, int x, int y) { return (im.at(x, y, 0) + im.at(x, y, 1) + im.at(x, y, 2)) / 3.0; };
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  double sum = 0;
  int count = 0;
  for (int y0 = 0; y0 + 8 <= a.height(); y0 += 4)
    for (int x0 = 0; x0 + 8 <= a.width(); x0 += 4) {
      double ma = 0, mb = 0, va = 0, vb = 0, cov = 0;
      for (int y = y0; y < y0 + 8; ++y)
        for (int x = x0; x < x0 + 8; ++x) ma += lum(a, x, y) / 64, mb += lum(b, x, y) / 64;
      for (int y = y0; y < y0 + 8; ++y)
        for (int x = x0; x < x0 + 8; ++x) {
          const double da = lum(a, x, y) - ma, db = lum(b, x, y) - mb;
          va += da * da / 63, vb += db * db / 63, cov += da * db / 63;
        }
      sum += (2 * ma * mb + c1) * (2 * cov + c2) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
      ++count;
    }
  return sum / count;
}

// Mean squared difference between horizontal and vertical neighbours.
inline double gradient_energy(const Image& im) {
  double sum = 0;
  for (int y = 0; y + 1 < im.height(); ++y)
    for (int x = 0; x + 1 < im.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const double gx = im.at(x + 1, y, c) - im.at(x, y, c), gy = im.at(x, y + 1, c) - im.at(x, y, c);
        sum += gx * gx + gy * gy;
      }
  return sum / double((im.width() - 1) * (im.height() - 1) * 3);
}

}  // namespace tempera::test

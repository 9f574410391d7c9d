#include "tempera/engine/color.hpp"

#include <algorithm>
#include <cmath>

namespace tempera {
namespace {

double linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }
double lab_f(double t) { return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0; }

double encoded(double c) { return c <= 0.0031308 ? c * 12.92 : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055; }

}  // namespace

Image linear_to_srgb(const ImageView& linear) {
  Image out = Image::copy_of(linear);
  const int colour = std::min(linear.channels, 3);
  for (std::size_t i = 0; i < linear.pixel_count(); ++i) {
    float* p = out.data() + i * linear.channels;
    for (int c = 0; c < colour; ++c) p[c] = std::isnan(p[c]) ? 0.0f : float(encoded(std::clamp<double>(p[c], 0, 1)));
  }
  return out;
}

Image srgb_to_lab(const ImageView& rgb) {
  Image out = Image::copy_of(rgb);
  if (rgb.channels < 3) return out;
  for (std::size_t i = 0; i < rgb.pixel_count(); ++i) {
    float* p = out.data() + i * rgb.channels;
    const double r = linear(std::clamp<double>(p[0], 0, 1)), g = linear(std::clamp<double>(p[1], 0, 1)),
                 b = linear(std::clamp<double>(p[2], 0, 1));
    const double x = (0.4124564 * r + 0.3575761 * g + 0.1804375 * b) / 0.95047;
    const double y = 0.2126729 * r + 0.7151522 * g + 0.0721750 * b;
    const double z = (0.0193339 * r + 0.1191920 * g + 0.9503041 * b) / 1.08883;
    const double fx = lab_f(x), fy = lab_f(y), fz = lab_f(z);
    p[0] = float((116.0 * fy - 16.0) / 100.0);
    p[1] = float(500.0 * (fx - fy) / 100.0);
    p[2] = float(200.0 * (fy - fz) / 100.0);
  }
  return out;
}

}  // namespace tempera

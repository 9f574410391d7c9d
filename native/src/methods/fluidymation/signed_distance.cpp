#include "tempera/methods/fluidymation/signed_distance.hpp"

#include <algorithm>
#include <cmath>

#include "tempera/engine/distance_transform.hpp"
#include "tempera/engine/error.hpp"

namespace tempera {

Image signed_distance(const ImageView& mask) {
  const Image to_inside = euclidean_distance(mask, "mask");
  Image outside(mask.width, mask.height, 1);
  for (std::size_t i = 0; i < outside.pixel_count(); ++i) outside.data()[i] = mask.data[i] > 0.5f ? 0.0f : 1.0f;
  const Image to_outside = euclidean_distance(outside.view(), "mask");
  const float cap = std::hypot(float(mask.width), float(mask.height));
  Image out(mask.width, mask.height, 1);
  for (std::size_t i = 0; i < out.pixel_count(); ++i) {
    const bool in = mask.data[i] > 0.5f;
    const float d = in ? to_outside.data()[i] : to_inside.data()[i];
    out.data()[i] = (in ? 1.0f : -1.0f) * (std::min(d, cap) - 0.5f);
  }
  return out;
}

Image gradient(const ImageView& f) {
  if (f.channels != 1) throw ValueError(concat("gradient needs a 1-channel field, got ", f.channels));
  Image g(f.width, f.height, 2);
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const int x0 = std::max(0, x - 1), x1 = std::min(f.width - 1, x + 1);
      const int y0 = std::max(0, y - 1), y1 = std::min(f.height - 1, y + 1);
      g.at(x, y, 0) = x1 > x0 ? (f.at(x1, y, 0) - f.at(x0, y, 0)) / float(x1 - x0) : 0.0f;
      g.at(x, y, 1) = y1 > y0 ? (f.at(x, y1, 0) - f.at(x, y0, 0)) / float(y1 - y0) : 0.0f;
    }
  return g;
}

}  // namespace tempera

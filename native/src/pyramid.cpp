#include "tempera/pyramid.hpp"

#include <algorithm>

namespace tempera {

Image downsample_half(const ImageView& image) {
  const int w = std::max(1, (image.width + 1) / 2), h = std::max(1, (image.height + 1) / 2);
  const int c = image.channels;
  Image out(w, h, c);
  for (int y = 0; y < h; ++y) {
    const int y0 = std::min(2 * y, image.height - 1), y1 = std::min(2 * y + 1, image.height - 1);
    for (int x = 0; x < w; ++x) {
      const int x0 = std::min(2 * x, image.width - 1), x1 = std::min(2 * x + 1, image.width - 1);
      const float *a = image.pixel(x0, y0), *b = image.pixel(x1, y0), *d = image.pixel(x0, y1),
                  *e = image.pixel(x1, y1);
      float* o = out.pixel(x, y);
      for (int k = 0; k < c; ++k) o[k] = 0.25f * (a[k] + b[k] + d[k] + e[k]);
    }
  }
  return out;
}

std::vector<Image> build_pyramid(const ImageView& image, int levels) {
  std::vector<Image> pyramid;
  pyramid.push_back(Image::copy_of(image));
  for (int i = 1; i < levels; ++i) pyramid.push_back(downsample_half(pyramid.back().view()));
  return pyramid;
}

int pyramid_levels_for(int width, int height, int min_side, int max_levels) {
  int levels = 1, side = std::min(width, height);
  while (levels < max_levels && side / 2 >= min_side) {
    side /= 2;
    ++levels;
  }
  return levels;
}

}  // namespace tempera

#include "tempera/methods/rigid/silhouette.hpp"

#include <algorithm>
#include <cmath>

#include "tempera/engine/distance_transform.hpp"
#include "tempera/engine/error.hpp"

namespace tempera {

namespace {

void require_mask(const ImageView& image, const char* what) {
  require_nonempty(image, what);
  if (image.channels != 1) throw ValueError(concat(what, " must have 1 channel, got ", image.channels));
}

}  // namespace

Image filled_silhouette(const ImageView& ink, float threshold) {
  require_mask(ink, "drawing");
  const int w = ink.width, h = ink.height;
  std::vector<char> outside(std::size_t(w) * std::size_t(h), 0);
  std::vector<int> stack;
  const auto push = [&](int x, int y) {
    const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
    if (outside[i] || ink.at(x, y, 0) > threshold) return;
    outside[i] = 1;
    stack.push_back(int(i));
  };
  for (int x = 0; x < w; ++x) push(x, 0), push(x, h - 1);
  for (int y = 0; y < h; ++y) push(0, y), push(w - 1, y);
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    const int x = i % w, y = i / w;
    if (x > 0) push(x - 1, y);
    if (x + 1 < w) push(x + 1, y);
    if (y > 0) push(x, y - 1);
    if (y + 1 < h) push(x, y + 1);
  }
  Image out(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float a = std::clamp(ink.at(x, y, 0), 0.0f, 1.0f);
      const bool out_region = outside[std::size_t(y) * std::size_t(w) + std::size_t(x)];
      // Anti-aliased stroke edges: outside they fade to 0, inside to 1.
      out.at(x, y, 0) = out_region ? 0.5f * a : (a > threshold ? 0.5f * a + (1 - a) : 1.0f);
    }
  return out;
}

std::vector<Vec2> iso_points(const ImageView& image, float level) {
  require_nonempty(image, "image");
  std::vector<Vec2> out;
  const auto cross = [&](int x0, int y0, int x1, int y1) {
    const float a = image.at(x0, y0, 0) - level, b = image.at(x1, y1, 0) - level;
    if ((a < 0) == (b < 0)) return;
    const double t = a / double(a - b);
    out.push_back({x0 + t * (x1 - x0), y0 + t * (y1 - y0)});
  };
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      if (x + 1 < image.width) cross(x, y, x + 1, y);
      if (y + 1 < image.height) cross(x, y, x, y + 1);
    }
  return out;
}

namespace {

// Mean over a's ink of the distance (px) to b's nearest ink.
double directed_chamfer(const ImageView& a, const ImageView& b) {
  const float d_max = float(std::max(b.width, b.height));
  const Image dist = line_distance(b, d_max);
  double sum = 0;
  std::size_t n = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      if (a.at(x, y, 0) > 0.5f) sum += double(dist.at(x, y, 0)) * d_max, ++n;
  if (n == 0) throw ValueError("chamfer distance: a drawing has no ink");
  return sum / double(n);
}

}  // namespace

double chamfer_distance(const ImageView& a, const ImageView& b) {
  require_mask(a, "first drawing");
  require_mask(b, "second drawing");
  require_same_size(a, "first drawing", b, "second drawing");
  return 0.5 * (directed_chamfer(a, b) + directed_chamfer(b, a));
}

double iou(const ImageView& a, const ImageView& b) {
  require_mask(a, "first mask");
  require_mask(b, "second mask");
  require_same_size(a, "first mask", b, "second mask");
  std::size_t both = 0, either = 0;
  for (std::size_t i = 0; i < a.pixel_count(); ++i) {
    const bool pa = a.data[i] > 0.5f, pb = b.data[i] > 0.5f;
    both += pa && pb;
    either += pa || pb;
  }
  return either == 0 ? 1.0 : double(both) / double(either);
}

}  // namespace tempera

#include "tempera/methods/rigid/stroke_raster.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "tempera/engine/error.hpp"

namespace tempera {

namespace {

double segment_distance(Vec2 p, Vec2 a, Vec2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - a.x - t * dx, p.y - a.y - t * dy);
}

void require_one_channel(const Image& image, const char* what) {
  if (image.channels() != 1 || image.empty()) throw ValueError(concat(what, " must be a non-empty 1-channel image"));
}

}  // namespace

void draw_stroke(Image& ink, const std::vector<Vec2>& points, double width, bool closed) {
  require_one_channel(ink, "stroke ink");
  const std::size_t n = points.size();
  const std::size_t segments = closed ? n : (n == 0 ? 0 : n - 1);
  const double reach = width / 2 + 0.5;
  for (std::size_t s = 0; s < segments; ++s) {
    const Vec2 a = points[s], b = points[(s + 1) % n];
    const int x0 = std::max(0, int(std::floor(std::min(a.x, b.x) - reach)));
    const int x1 = std::min(ink.width() - 1, int(std::ceil(std::max(a.x, b.x) + reach)));
    const int y0 = std::max(0, int(std::floor(std::min(a.y, b.y) - reach)));
    const int y1 = std::min(ink.height() - 1, int(std::ceil(std::max(a.y, b.y) + reach)));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double c = std::clamp(reach - segment_distance({double(x), double(y)}, a, b), 0.0, 1.0);
        float& v = ink.at(x, y, 0);
        v = std::max(v, float(c));
      }
  }
}

void fill_polygon(Image& mask, const std::vector<Vec2>& polygon) {
  require_one_channel(mask, "polygon mask");
  if (polygon.size() < 3) return;
  double xmin = polygon[0].x, xmax = xmin, ymin = polygon[0].y, ymax = ymin;
  for (const Vec2& p : polygon) {
    xmin = std::min(xmin, p.x), xmax = std::max(xmax, p.x);
    ymin = std::min(ymin, p.y), ymax = std::max(ymax, p.y);
  }
  const int x0 = std::max(0, int(std::floor(xmin)) - 1), x1 = std::min(mask.width() - 1, int(std::ceil(xmax)) + 1);
  const int y0 = std::max(0, int(std::floor(ymin)) - 1), y1 = std::min(mask.height() - 1, int(std::ceil(ymax)) + 1);
  std::vector<int> hits(std::size_t(std::max(0, x1 - x0 + 1)));
  std::vector<double> crossings;
  for (int y = y0; y <= y1; ++y) {
    std::fill(hits.begin(), hits.end(), 0);
    for (int sy = 0; sy < 4; ++sy) {
      // Even-odd rule along the sub-row: sorted edge crossings bound the spans.
      const double ys = y - 0.375 + 0.25 * sy;
      crossings.clear();
      for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
        const Vec2 a = polygon[i], b = polygon[j];
        if ((a.y > ys) != (b.y > ys)) crossings.push_back((b.x - a.x) * (ys - a.y) / (b.y - a.y) + a.x);
      }
      std::sort(crossings.begin(), crossings.end());
      for (int x = x0; x <= x1; ++x)
        for (int sx = 0; sx < 4; ++sx) {
          const double xs = x - 0.375 + 0.25 * sx;
          const auto left = std::lower_bound(crossings.begin(), crossings.end(), xs) - crossings.begin();
          hits[std::size_t(x - x0)] += int(left % 2);
        }
    }
    for (int x = x0; x <= x1; ++x) {
      float& v = mask.at(x, y, 0);
      v = std::max(v, hits[std::size_t(x - x0)] / 16.0f);
    }
  }
}

}  // namespace tempera

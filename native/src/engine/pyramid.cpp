#include "tempera/engine/pyramid.hpp"

#include <algorithm>
#include <cmath>

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

int pyramid_levels_for(int width, int height, int min_side, int max_levels, double ratio) {
  int levels = 1;
  if (ratio == 0.5) {  // the integer rule of the 2x pyramid
    int side = std::min(width, height);
    while (levels < max_levels && side / 2 >= min_side) {
      side /= 2;
      ++levels;
    }
    return levels;
  }
  double side = std::min(width, height);
  while (levels < max_levels && side * ratio >= min_side) {
    side *= ratio;
    ++levels;
  }
  return levels;
}

std::vector<std::pair<int, int>> level_sizes(int width, int height, int levels, double ratio) {
  std::vector<std::pair<int, int>> out{{width, height}};
  for (int l = 1; l < levels; ++l) {
    if (ratio == 0.5) {
      const auto [w, h] = out.back();
      out.emplace_back(std::max(1, (w + 1) / 2), std::max(1, (h + 1) / 2));
    } else {
      const double k = std::pow(ratio, l);
      out.emplace_back(std::max(1, int(std::lround(width * k))), std::max(1, int(std::lround(height * k))));
    }
  }
  return out;
}

namespace {

// Weights of the input pixels that output pixel i covers along one axis.
struct Span {
  int first = 0;
  std::vector<float> weights;
};

std::vector<Span> area_spans(int in, int out) {
  std::vector<Span> spans(out);
  const double scale = double(in) / out;
  for (int i = 0; i < out; ++i) {
    const double a = i * scale, b = (i + 1) * scale;
    Span& s = spans[i];
    s.first = int(std::floor(a));
    for (int j = s.first; j < std::min(in, int(std::ceil(b))); ++j)
      s.weights.push_back(float((std::min(b, j + 1.0) - std::max(a, double(j))) / scale));
  }
  return spans;
}

// One axis of a separable filter given as spans, x (horizontal) or y.
Image apply_spans(const ImageView& in, const std::vector<Span>& spans, bool horizontal) {
  const int c = in.channels;
  const int w = horizontal ? int(spans.size()) : in.width, h = horizontal ? in.height : int(spans.size());
  Image out(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Span& s = spans[horizontal ? x : y];
      float* o = out.pixel(x, y);
      for (std::size_t k = 0; k < s.weights.size(); ++k) {
        const int j = s.first + int(k);
        const float* p = horizontal ? in.pixel(j, y) : in.pixel(x, j);
        for (int ch = 0; ch < c; ++ch) o[ch] += s.weights[k] * p[ch];
      }
    }
  return out;
}

std::vector<Span> box_spans(int n, float width) {
  std::vector<Span> spans(n);
  const float half = 0.5f * width;
  for (int i = 0; i < n; ++i) {
    const float a = i + 0.5f - half, b = i + 0.5f + half;
    Span& s = spans[i];
    s.first = std::max(0, int(std::floor(a)));
    const int last = std::min(n - 1, int(std::ceil(b)) - 1);
    float total = 0;
    for (int j = s.first; j <= last; ++j) {
      const float wgt = std::min(b, j + 1.0f) - std::max(a, float(j));
      s.weights.push_back(std::max(0.0f, wgt));
      total += s.weights.back();
    }
    for (auto& v : s.weights) v /= total;  // clamped border: renormalize
  }
  return spans;
}

}  // namespace

Image resize_area(const ImageView& image, int width, int height) {
  const Image rows = apply_spans(image, area_spans(image.width, width), true);
  return apply_spans(rows.view(), area_spans(image.height, height), false);
}

Image box_blur(const ImageView& image, float width) {
  if (width <= 1.0f) return Image::copy_of(image);
  const Image rows = apply_spans(image, box_spans(image.width, width), true);
  return apply_spans(rows.view(), box_spans(image.height, width), false);
}

std::vector<Image> build_pyramid(const ImageView& image, int levels, double ratio,
                                 const std::vector<float>& box_widths) {
  return build_pyramid(Image::copy_of(image), levels, ratio, box_widths);
}

std::vector<Image> build_pyramid(Image&& image, int levels, double ratio, const std::vector<float>& box_widths) {
  const auto sizes = level_sizes(image.width(), image.height(), levels, ratio);
  std::vector<Image> pyramid;
  pyramid.push_back(std::move(image));
  for (std::size_t l = 1; l < sizes.size(); ++l)
    pyramid.push_back(ratio == 0.5 ? downsample_half(pyramid.back().view())
                                   : resize_area(pyramid.front().view(), sizes[l].first, sizes[l].second));
  for (std::size_t l = 0; l < pyramid.size() && l < box_widths.size(); ++l)
    if (box_widths[l] > 1.0f) pyramid[l] = box_blur(pyramid[l].view(), box_widths[l]);
  return pyramid;
}

}  // namespace tempera

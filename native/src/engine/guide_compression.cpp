#include "tempera/engine/guide_compression.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "tempera/engine/error.hpp"

namespace tempera {

void symmetric_eigen(std::vector<double> a, int n, std::vector<double>& values, std::vector<double>& vectors) {
  std::vector<double> v(std::size_t(n) * n, 0.0);
  for (int i = 0; i < n; ++i) v[i * n + i] = 1.0;
  for (int sweep = 0; sweep < 100; ++sweep) {
    double off = 0;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) off += a[i * n + j] * a[i * n + j];
    if (off < 1e-24) break;
    for (int p = 0; p < n; ++p)
      for (int q = p + 1; q < n; ++q) {
        const double apq = a[p * n + q];
        if (std::abs(apq) < 1e-300) continue;
        const double theta = (a[q * n + q] - a[p * n + p]) / (2 * apq);
        const double t = (theta >= 0 ? 1 : -1) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < n; ++k) {  // A <- A J (columns p, q)
          const double akp = a[k * n + p], akq = a[k * n + q];
          a[k * n + p] = c * akp - s * akq;
          a[k * n + q] = s * akp + c * akq;
        }
        for (int k = 0; k < n; ++k) {  // A <- J^T A (rows p, q)
          const double apk = a[p * n + k], aqk = a[q * n + k];
          a[p * n + k] = c * apk - s * aqk;
          a[q * n + k] = s * apk + c * aqk;
        }
        for (int k = 0; k < n; ++k) {  // V <- V J
          const double vkp = v[k * n + p], vkq = v[k * n + q];
          v[k * n + p] = c * vkp - s * vkq;
          v[k * n + q] = s * vkp + c * vkq;
        }
      }
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int x, int y) { return a[x * n + x] > a[y * n + y]; });
  values.resize(n);
  vectors.resize(std::size_t(n) * n);
  for (int r = 0; r < n; ++r) {
    values[r] = a[order[r] * n + order[r]];
    for (int k = 0; k < n; ++k) vectors[r * n + k] = v[k * n + order[r]];
  }
}

int WeightedGuides::channels() const {
  int n = 0;
  for (const auto& layer : layers) n += layer.channels;
  return n;
}

void WeightedGuides::pixel(std::size_t i, float* out) const {
  for (std::size_t k = 0; k < layers.size(); ++k) {
    const ImageView& layer = layers[k];
    for (int c = 0; c < layer.channels; ++c) *out++ = layer.data[i * std::size_t(layer.channels) + c] * scales[k];
  }
}

Image WeightedGuides::stacked() const {
  const ImageView& first = layers.front();
  Image out(first.width, first.height, channels());
  for (std::size_t i = 0; i < out.pixel_count(); ++i) pixel(i, out.data() + i * std::size_t(out.channels()));
  return out;
}

namespace {

// Calls fn(pixel) on a regular subsample of the images read as one (rows of
// the first, then of the next, ...): a subsample is plenty for a covariance.
template <class Fn>
void visit_subsample(const std::vector<const WeightedGuides*>& images, int n, Fn&& fn) {
  std::size_t total = 0;
  for (const WeightedGuides* g : images) total += g->pixel_count();
  const std::size_t step = std::max<std::size_t>(1, total / 65536);
  std::vector<float> px(static_cast<std::size_t>(n));
  std::size_t first = 0;  // index of the current image's first pixel in the whole
  for (const WeightedGuides* g : images) {
    for (std::size_t i = (step - first % step) % step; i < g->pixel_count(); i += step) {
      g->pixel(i, px.data());
      fn(px.data());
    }
    first += g->pixel_count();
  }
}

}  // namespace

GuideProjection fit_guide_projection(const std::vector<WeightedGuides>& sources, const WeightedGuides& target,
                                     double keep) {
  const int n = target.channels();
  for (const auto& s : sources)
    if (s.channels() != n) throw ValueError("internal: guide channel counts differ");
  GuideProjection proj;
  proj.input_channels = n;
  // Mean and covariance over the sources and the target, each side
  // subsampled on its own.
  std::vector<const WeightedGuides*> source_images;
  for (const auto& s : sources) source_images.push_back(&s);
  const std::vector<const WeightedGuides*> sides[2] = {source_images, {&target}};
  std::vector<double> mean(n, 0.0), cov(std::size_t(n) * n, 0.0);
  std::size_t count = 0;
  for (const auto& side : sides)
    visit_subsample(side, n, [&](const float* px) {
      for (int c = 0; c < n; ++c) mean[c] += px[c];
      ++count;
    });
  for (auto& m : mean) m /= double(count);
  for (const auto& side : sides)
    visit_subsample(side, n, [&](const float* px) {
      for (int i = 0; i < n; ++i)
        for (int j = i; j < n; ++j) cov[i * n + j] += (px[i] - mean[i]) * (px[j] - mean[j]);
    });
  for (int i = 0; i < n; ++i)
    for (int j = i; j < n; ++j) cov[j * n + i] = cov[i * n + j] /= double(count);
  std::vector<double> values, vectors;
  symmetric_eigen(cov, n, values, vectors);
  const double total = std::accumulate(values.begin(), values.end(), 0.0, [](double s, double v) {
    return s + std::max(v, 0.0);
  });
  int k = 0;
  double kept = 0;
  while (k < n && (k == 0 || kept < keep * total)) kept += std::max(values[k++], 0.0);
  proj.kept_variance = total > 0 ? kept / total : 1.0;
  proj.mean.assign(mean.begin(), mean.end());
  proj.components.assign(vectors.begin(), vectors.begin() + std::size_t(k) * n);
  return proj;
}

Image GuideProjection::apply(const WeightedGuides& guides) const {
  const int n = input_channels, k = output_channels();
  const ImageView& first = guides.layers.front();
  Image out(first.width, first.height, k);
  std::vector<float> px(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < guides.pixel_count(); ++i) {
    guides.pixel(i, px.data());
    float* o = out.data() + i * k;
    for (int r = 0; r < k; ++r) {
      float s = 0;
      for (int c = 0; c < n; ++c) s += components[r * n + c] * (px[c] - mean[c]);
      o[r] = s;
    }
  }
  return out;
}

}  // namespace tempera

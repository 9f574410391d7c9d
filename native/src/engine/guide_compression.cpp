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

GuideProjection fit_guide_projection(const ImageView& source, const ImageView& target, double keep) {
  if (source.channels != target.channels) throw ValueError("internal: guide channel counts differ");
  const int n = source.channels;
  GuideProjection proj;
  proj.input_channels = n;
  // Mean and covariance over both images (a regular subsample is plenty).
  std::vector<double> mean(n, 0.0), cov(std::size_t(n) * n, 0.0);
  std::size_t count = 0;
  auto visit = [&](const ImageView& img, auto&& fn) {
    const std::size_t step = std::max<std::size_t>(1, img.pixel_count() / 65536);
    for (std::size_t i = 0; i < img.pixel_count(); i += step) fn(img.data + i * n);
  };
  for (const ImageView* img : {&source, &target})
    visit(*img, [&](const float* px) {
      for (int c = 0; c < n; ++c) mean[c] += px[c];
      ++count;
    });
  for (auto& m : mean) m /= double(count);
  for (const ImageView* img : {&source, &target})
    visit(*img, [&](const float* px) {
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

Image GuideProjection::apply(const ImageView& guides) const {
  const int n = input_channels, k = output_channels();
  Image out(guides.width, guides.height, k);
  for (std::size_t i = 0; i < guides.pixel_count(); ++i) {
    const float* px = guides.data + i * n;
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

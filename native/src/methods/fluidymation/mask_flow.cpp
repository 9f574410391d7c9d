#include "tempera/methods/fluidymation/mask_flow.hpp"

#include <algorithm>
#include <cmath>

#include "tempera/engine/error.hpp"
#include "tempera/engine/parallel.hpp"
#include "tempera/methods/fluidymation/signed_distance.hpp"

namespace tempera {
namespace {

constexpr int kMaxSweeps = 1000;

bool inside(const ImageView& mask, std::size_t i) { return mask.data[i] > 0.5f; }

// Inside pixels next to the outside (distance below one pixel): where the
// boundary's motion is measured.
bool on_boundary(const Image& dist, std::size_t i) { return dist.data()[i] > 0.0f && dist.data()[i] < 1.0f; }

// Known values averaged 2x2 down (weights = known count), for the coarse guess.
void pull(const Image& v, const Image& w, Image& cv, Image& cw) {
  const int cwid = (v.width() + 1) / 2, chei = (v.height() + 1) / 2;
  cv = Image(cwid, chei, 2);
  cw = Image(cwid, chei, 1);
  for (int y = 0; y < v.height(); ++y)
    for (int x = 0; x < v.width(); ++x) {
      const float k = w.at(x, y, 0);
      cw.at(x / 2, y / 2, 0) += k;
      for (int c = 0; c < 2; ++c) cv.at(x / 2, y / 2, c) += k * v.at(x, y, c);
    }
  for (std::size_t i = 0; i < cw.pixel_count(); ++i) {
    if (cw.data()[i] <= 0) continue;
    for (int c = 0; c < 2; ++c) cv.data()[2 * i + c] /= cw.data()[i];
    cw.data()[i] = 1.0f;
  }
}

// Push-pull: every pixel without a known value gets the nearest coarser
// level's average of known values (a smooth first guess that the relaxation
// then only refines, instead of diffusing across the whole mask).
Image push_pull(const Image& v, const Image& w) {
  if (v.width() <= 1 && v.height() <= 1) return v;
  Image cv, cw;
  pull(v, w, cv, cw);
  const Image coarse = push_pull(cv, cw);
  Image out = v;
  for (int y = 0; y < v.height(); ++y)
    for (int x = 0; x < v.width(); ++x)
      if (w.at(x, y, 0) <= 0)
        for (int c = 0; c < 2; ++c) out.at(x, y, c) = coarse.at(x / 2, y / 2, c);
  return out;
}

// The distance fields convolved with a temporal Gaussian (sigma = radius / 2,
// taps out to the radius). Near the sequence's ends the window shrinks to
// stay symmetric (k = the frames to the nearer end): a one-sided window
// there would bend a steadily moving boundary and slow its flow, by half
// at the first frame.
std::vector<Image> smooth_in_time(const std::vector<Image>& dist, float radius) {
  if (radius <= 0) return dist;
  const int n = int(dist.size()), r = int(std::ceil(radius));
  const float sigma = radius / 2.0f;
  std::vector<Image> out(dist.size());
  parallel_for(n, 0, [&](int i) {
    Image f(dist[0].width(), dist[0].height(), 1);
    double wsum = 0;
    const int k = std::min({r, i, n - 1 - i});
    for (int d = -k; d <= k; ++d) {
      const float wt = std::exp(-0.5f * float(d * d) / (sigma * sigma));
      wsum += wt;
      const Image& src = dist[std::size_t(i + d)];
      for (std::size_t p = 0; p < f.pixel_count(); ++p) f.data()[p] += wt * src.data()[p];
    }
    for (std::size_t p = 0; p < f.pixel_count(); ++p) f.data()[p] = float(f.data()[p] / wsum);
    out[std::size_t(i)] = std::move(f);
  });
  return out;
}

}  // namespace

Image diffuse_fill(const ImageView& values, const ImageView& known, const ImageView& mask) {
  const int w = mask.width, h = mask.height;
  Image v(w, h, 2), k(w, h, 1);
  for (std::size_t i = 0; i < mask.pixel_count(); ++i)
    if (known.data[i] > 0.5f) {
      k.data()[i] = 1.0f;
      for (int c = 0; c < 2; ++c) v.data()[2 * i + c] = values.data[2 * i + c];
    }
  Image cur = push_pull(v, k);
  // Red-black successive over-relaxation with the optimal factor for the
  // mask's extent (Young): converges in about that many sweeps where plain
  // Jacobi would need its square. Neighbours outside the mask are left out
  // (a zero-flux border). One thread per fill (flow_from_masks runs frames
  // in parallel), in a fixed order: deterministic.
  const int extent = std::max(w, h);
  const float omega = 2.0f / (1.0f + std::sin(3.14159265f / float(extent)));
  const int sweeps = std::min(kMaxSweeps, extent + 20);
  std::vector<std::size_t> free[2];  // the unknown inside pixels, by colour
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      if (inside(mask, i) && k.data()[i] <= 0) free[(x + y) % 2].push_back(i);
    }
  for (int sweep = 0; sweep < sweeps; ++sweep)
    for (const auto& pixels : free)
      for (std::size_t i : pixels) {
        const int x = int(i % std::size_t(w)), y = int(i / std::size_t(w));
        float sum[2] = {0, 0};
        int n = 0;
        const int nb[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
        for (const auto& q : nb) {
          if (q[0] < 0 || q[1] < 0 || q[0] >= w || q[1] >= h) continue;
          const std::size_t j = std::size_t(q[1]) * w + q[0];
          if (!inside(mask, j)) continue;
          sum[0] += cur.data()[2 * j], sum[1] += cur.data()[2 * j + 1], ++n;
        }
        if (!n) continue;
        for (int c = 0; c < 2; ++c) cur.data()[2 * i + c] += omega * (sum[c] / n - cur.data()[2 * i + c]);
      }
  for (std::size_t i = 0; i < mask.pixel_count(); ++i)
    if (!inside(mask, i)) cur.data()[2 * i] = cur.data()[2 * i + 1] = 0;
  return cur;
}

std::vector<Image> flow_from_masks(const std::vector<ImageView>& masks, float temporal_radius) {
  if (masks.size() < 2) throw ValueError(concat("flow from masks needs at least 2 masks, got ", masks.size()));
  if (!(temporal_radius >= 0) || !std::isfinite(temporal_radius))
    throw ValueError(concat("temporal radius must be >= 0, got ", temporal_radius));
  for (std::size_t i = 0; i < masks.size(); ++i) {
    require_nonempty(masks[i], concat("mask ", i));
    if (masks[i].channels != 1) throw ValueError(concat("mask ", i, " must have 1 channel, got ", masks[i].channels));
    require_same_size(masks[i], concat("mask ", i), masks[0], "mask 0");
  }
  const std::size_t n = masks.size();
  std::vector<Image> raw_dist(n);
  parallel_for(int(n), 0, [&](int i) { raw_dist[std::size_t(i)] = signed_distance(masks[std::size_t(i)]); });
  const std::vector<Image> dist = smooth_in_time(raw_dist, temporal_radius);
  std::vector<Image> flows(n);
  parallel_for(int(n), 0, [&](int frame) {
    const std::size_t i = std::size_t(frame);
    // The last frame measures its boundary against the frame before.
    const std::size_t a = i + 1 < n ? i : i - 1, b = a + 1;
    const Image g = gradient(dist[i].view());
    Image boundary(masks[i].width, masks[i].height, 2), known(masks[i].width, masks[i].height, 1);
    for (std::size_t p = 0; p < boundary.pixel_count(); ++p) {
      if (!on_boundary(raw_dist[i], p)) continue;
      const float gx = g.data()[2 * p], gy = g.data()[2 * p + 1], len = std::hypot(gx, gy);
      if (len < 1e-6f) continue;
      const float speed = -(dist[b].data()[p] - dist[a].data()[p]);
      boundary.data()[2 * p] = speed * gx / len, boundary.data()[2 * p + 1] = speed * gy / len;
      known.data()[p] = 1.0f;
    }
    flows[i] = diffuse_fill(boundary.view(), known.view(), masks[i]);
  });
  return flows;
}

}  // namespace tempera

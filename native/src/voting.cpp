#include "tempera/voting.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "tempera/parallel.hpp"
#include "tempera/rng.hpp"

namespace tempera {
namespace {

// Kernel width of the weighted mode, in colour units: candidates within about
// this distance of each other count as the same colour.
constexpr float kModeBandwidth = 0.1f;

struct Voter {
  const ImageView& style;
  const PatchSpace& space;
  const OffsetField& field;

  // The pixel that the patch of target q (centred at its match) puts at
  // offset (dx, dy) from its centre.
  void sample(std::size_t qi, int qx, int qy, int dx, int dy, float* out) const {
    const int px = field.x[qi], py = field.y[qi], c = style.channels;
    if (space.rotated()) {
      float ox, oy;
      rotate_offset(space.rotation(px, py, qx, qy), float(dx), float(dy), ox, oy);
      sample_bilinear(style.data, style.width, style.height, c, c, px + ox, py + oy, out);
    } else {
      const float* s = style.pixel(px + dx, py + dy);
      std::copy(s, s + c, out);
    }
  }
};

// Index of the candidate with the most similar neighbours (a kernel mode).
std::size_t weighted_mode(const std::vector<float>& values, int c, std::size_t n) {
  std::size_t best = 0;
  float best_score = -1.0f;
  const float inv = 1.0f / (kModeBandwidth * kModeBandwidth);
  for (std::size_t j = 0; j < n; ++j) {
    float score = 0.0f;
    for (std::size_t k = 0; k < n; ++k) {
      float d = 0.0f;
      for (int ch = 0; ch < c; ++ch) {
        const float e = values[j * c + ch] - values[k * c + ch];
        d += e * e;
      }
      score += std::exp(-d * inv);
    }
    if (score > best_score) best_score = score, best = j;
  }
  return best;
}

}  // namespace

Image vote(const ImageView& style, const PatchSpace& space, const SearchConstraints& cons, const OffsetField& field,
           const ImageView& previous, const VoteParams& params) {
  const int tw = field.width, th = field.height, c = style.channels, r = space.radius;
  const std::vector<std::uint8_t>& voters = params.voters ? *params.voters : cons.target_active;
  Image out(tw, th, c);
  if (!previous.empty()) std::copy_n(previous.data, previous.size(), out.data());
  const Voter voter{style, space, field};
  parallel_for(th, params.threads, [&](int ty) {
    std::vector<float> sum(c), sample(c), candidates;
    for (int tx = 0; tx < tw; ++tx) {
      const std::size_t i = field.index(tx, ty);
      if (!cons.target_active[i]) continue;
      float* o = out.pixel(tx, ty);
      if (params.mode == OutputMode::Centre) {
        // The pixel under the (sub-pixel) source position, no blending.
        const int sx = std::clamp(int(std::lround(field.position_x(i))), 0, style.width - 1);
        const int sy = std::clamp(int(std::lround(field.position_y(i))), 0, style.height - 1);
        std::copy_n(style.pixel(sx, sy), c, o);
        continue;
      }
      std::fill(sum.begin(), sum.end(), 0.0f);
      candidates.clear();
      int count = 0;
      // Gather from every patch (centred at q') that covers q; q - q' is the
      // offset of q inside that patch.
      for (int dy = -r; dy <= r; ++dy) {
        const int qy = ty - dy;
        if (qy < 0 || qy >= th) continue;
        for (int dx = -r; dx <= r; ++dx) {
          const int qx = tx - dx;
          if (qx < 0 || qx >= tw) continue;
          const std::size_t qi = field.index(qx, qy);
          if (!voters[qi]) continue;
          voter.sample(qi, qx, qy, dx, dy, sample.data());
          if (params.mode == OutputMode::Mean)
            for (int k = 0; k < c; ++k) sum[k] += sample[k];
          else
            candidates.insert(candidates.end(), sample.begin(), sample.end());
          ++count;
        }
      }
      if (count == 0) continue;
      if (params.mode == OutputMode::Mean) {
        for (int k = 0; k < c; ++k) o[k] = sum[k] / float(count);
      } else {
        std::size_t pick = 0;
        if (params.mode == OutputMode::Random) {
          Rng rng(params.seed, mix64(params.stream * 0x9E37ull + 17) ^ i);
          pick = std::size_t(rng.below(count));
        } else {
          pick = weighted_mode(candidates, c, std::size_t(count));
        }
        std::copy_n(candidates.data() + pick * c, c, o);
      }
    }
  });
  return out;
}

}  // namespace tempera

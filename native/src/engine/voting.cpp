#include "tempera/engine/voting.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "tempera/engine/parallel.hpp"
#include "tempera/engine/rng.hpp"

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

// Index of the candidate with the most similar neighbours (a kernel mode):
// score(j) = sum over k of exp(-|v_j - v_k|^2 / h^2), the first best wins.
// This was the whole cost of a Color Me Noisy frame (93%: 49^2 kernels per
// pixel), so it is computed without changing the answer:
//  - equal colours (neighbouring patches of a coherent field copy the same
//    source pixel) are scored once, with their count as weight;
//  - each pair's kernel is evaluated once, for both ends;
//  - a kernel below half a float step of 1 is skipped: every score starts at
//    its own count (>= 1), so adding it could not change the sum.
struct ModeScratch {
  std::vector<float> unique, score;
  std::vector<std::size_t> first, count;
};

std::size_t weighted_mode(const std::vector<float>& values, int c, std::size_t n, ModeScratch& m) {
  m.unique.clear(), m.first.clear(), m.count.clear();
  for (std::size_t j = 0; j < n; ++j) {
    const float* v = values.data() + j * c;
    std::size_t u = 0;
    while (u < m.first.size() && !std::equal(v, v + c, m.unique.data() + u * c)) ++u;
    if (u == m.first.size()) {
      m.unique.insert(m.unique.end(), v, v + c);
      m.first.push_back(j);
      m.count.push_back(0);
    }
    ++m.count[u];
  }
  const std::size_t u = m.first.size();
  const float inv = 1.0f / (kModeBandwidth * kModeBandwidth);
  constexpr float kNegligible = 17.5f;  // exp(-17.5) < 2^-25
  m.score.assign(m.count.begin(), m.count.end());
  for (std::size_t j = 0; j < u; ++j)
    for (std::size_t k = j + 1; k < u; ++k) {
      float d = 0.0f;
      for (int ch = 0; ch < c; ++ch) {
        const float e = m.unique[j * c + ch] - m.unique[k * c + ch];
        d += e * e;
      }
      if (d * inv > kNegligible) continue;
      const float kernel = std::exp(-d * inv);
      m.score[j] += float(m.count[k]) * kernel;
      m.score[k] += float(m.count[j]) * kernel;
    }
  std::size_t best = 0;  // in order of first appearance, so ties go to the first candidate
  for (std::size_t j = 1; j < u; ++j)
    if (m.score[j] > m.score[best]) best = j;
  return m.first[best];
}

// Calls fn(q, dx, dy) for every voting patch that covers target (tx, ty),
// row by row: the patch centred at q = (tx - dx, ty - dy), in which the
// target is at offset (dx, dy). Returns how many there were. Every vote
// gathers in this order, so its sums are the same floats in every loop.
template <class Fn>
[[gnu::always_inline]] inline int for_each_covering_patch(const OffsetField& field,
                                                           const std::vector<std::uint8_t>& voters, int r, int tx,
                                                           int ty, Fn&& fn) {
  int count = 0;
  for (int dy = -r; dy <= r; ++dy) {
    const int qy = ty - dy;
    if (qy < 0 || qy >= field.height) continue;
    for (int dx = -r; dx <= r; ++dx) {
      const int qx = tx - dx;
      if (qx < 0 || qx >= field.width) continue;
      const std::size_t qi = field.index(qx, qy);
      if (!voters[qi]) continue;
      fn(qi, dx, dy);
      ++count;
    }
  }
  return count;
}

// Mean votes of axis-aligned patches, the EM loop's M-step: the same sums in
// the same order as the general loop below (so the same floats), without its
// per-sample copies and branches; it was a tenth of a StyLit frame.
constexpr int kMeanVoteChannels = 8;

void vote_mean_row(const ImageView& style, const OffsetField& field, const std::vector<std::uint8_t>& active,
                   const std::vector<std::uint8_t>& voters, int r, int ty, Image& out) {
  const int c = style.channels;
  for (int tx = 0; tx < field.width; ++tx) {
    const std::size_t i = field.index(tx, ty);
    if (!active[i]) continue;
    float sum[kMeanVoteChannels] = {};
    const int count = for_each_covering_patch(field, voters, r, tx, ty, [&](std::size_t qi, int dx, int dy) {
      const float* s = style.pixel(field.x[qi] + dx, field.y[qi] + dy);
      for (int k = 0; k < c; ++k) sum[k] += s[k];
    });
    if (count == 0) continue;
    float* o = out.pixel(tx, ty);
    for (int k = 0; k < c; ++k) o[k] = sum[k] / float(count);
  }
}

}  // namespace

Image vote(const ImageView& style, const PatchSpace& space, const SearchConstraints& cons, const OffsetField& field,
           const ImageView& previous, const VoteParams& params) {
  const int tw = field.width, th = field.height, c = style.channels, r = space.radius;
  const std::vector<std::uint8_t>& voters = params.voters ? *params.voters : cons.target_active;
  Image out(tw, th, c);
  if (!previous.empty()) std::copy_n(previous.data, previous.size(), out.data());
  if (params.mode == OutputMode::Mean && !space.rotated() && c <= kMeanVoteChannels) {
    parallel_for(th, params.threads, [&](int ty) { vote_mean_row(style, field, cons.target_active, voters, r, ty, out); });
    return out;
  }
  const Voter voter{style, space, field};
  parallel_for(th, params.threads, [&](int ty) {
    std::vector<float> sum(c), sample(c), candidates;
    ModeScratch scratch;
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
      const int count = for_each_covering_patch(field, voters, r, tx, ty, [&](std::size_t qi, int dx, int dy) {
        voter.sample(qi, tx - dx, ty - dy, dx, dy, sample.data());
        if (params.mode == OutputMode::Mean)
          for (int k = 0; k < c; ++k) sum[k] += sample[k];
        else
          candidates.insert(candidates.end(), sample.begin(), sample.end());
      });
      if (count == 0) continue;
      if (params.mode == OutputMode::Mean) {
        for (int k = 0; k < c; ++k) o[k] = sum[k] / float(count);
      } else {
        std::size_t pick = 0;
        if (params.mode == OutputMode::Random) {
          Rng rng(params.seed, mix64(params.stream * 0x9E37ull + 17) ^ i);
          pick = std::size_t(rng.below(count));
        } else {
          pick = weighted_mode(candidates, c, std::size_t(count), scratch);
        }
        std::copy_n(candidates.data() + pick * c, c, o);
      }
    }
  });
  return out;
}

}  // namespace tempera

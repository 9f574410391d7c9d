#include "tempera/engine/voting.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "tempera/engine/parallel.hpp"
#include "tempera/engine/rng.hpp"
#include "tempera/engine/weighted_mode.hpp"

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
  // offset (dx, dy) from its centre: the style's own pixel, or one sampled
  // into `buffer` between pixels (rotated patches).
  const float* sample(std::size_t qi, int qx, int qy, int dx, int dy, float* buffer) const {
    const int px = field.x[qi], py = field.y[qi], c = style.channels;
    if (!space.rotated()) return style.pixel(px + dx, py + dy);
    float ox, oy;
    rotate_offset(space.rotation(px, py, qx, qy), float(dx), float(dy), ox, oy);
    sample_bilinear(style.data, style.width, style.height, c, c, px + ox, py + oy, buffer);
    return buffer;
  }
};

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
    std::vector<float> sum(c), sample(c);
    ModeCandidates candidates;
    candidates.reset(c, std::size_t(2 * r + 1) * std::size_t(2 * r + 1));
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
        const float* v = voter.sample(qi, tx - dx, ty - dy, dx, dy, sample.data());
        if (params.mode == OutputMode::Mean)
          for (int k = 0; k < c; ++k) sum[k] += v[k];
        else
          candidates.push(v);
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
          pick = weighted_mode(candidates, kModeBandwidth, scratch);
        }
        candidates.copy(pick, o);
      }
    }
  });
  return out;
}

}  // namespace tempera

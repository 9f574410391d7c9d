// Bénard et al. 2013, eq. 5: g_sc = min(|M(p + d) - C(p, d)|^2, r_max), summed
// over the patch window with its weights. C(p, d) is where the candidate's
// patch puts the neighbour p + d; neighbours whose own match agrees make the
// candidate cheaper, so the field prefers large coherent pieces.
#include "tempera/engine/spatial_coherence.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstring>
#include <vector>

#include "tempera/engine/energy_term.hpp"
#include "tempera/engine/patchmatch.hpp"

namespace tempera {
namespace {

constexpr int kLanes = 8;

// The matched flags of up to 8 neighbours of a row (n of them), as bytes,
// built in a register: a short copy through memory stalled the load after it.
inline std::uint64_t matched_bytes(const std::uint8_t* m, int n) {
  std::uint64_t bytes = 0;
  if (n == kLanes) {
    std::memcpy(&bytes, m, kLanes);
    return bytes;
  }
  for (int j = 0; j < n; ++j) bytes |= std::uint64_t(m[j]) << (8 * j);
  return bytes;
}

// Lane j of the 8 accumulators, added as _mm256 lanes are: (0+4, 1+5, 2+6,
// 3+7), then (0+2, 1+3), then the two.
inline float lane_sum(const float* a) {
  const float s0 = a[0] + a[4], s1 = a[1] + a[5], s2 = a[2] + a[6], s3 = a[3] + a[7];
  return (s0 + s2) + (s1 + s3);
}

constexpr float kInf = std::numeric_limits<float>::infinity();

// Lane j of a group holds column i + j of the row (i = col0, col0 + 8, ...);
// both kernels add column k's products into lane (k - col0) % 8.
float patch_sum_scalar(const CoherencePatch& p, float limit) {
  const int side = 2 * p.radius + 1;
  float acc[kLanes] = {};
  for (int row = p.row0; row <= p.row1; ++row) {
    const std::size_t at = p.first + std::size_t(row - p.row0) * p.pitch - std::size_t(p.col0);  // column 0's index
    const int y = p.source_y - p.radius + row;
    for (int i = p.col0; i <= p.col1; i += kLanes) {
      const int n = std::min(kLanes, p.col1 - i + 1);
      for (int j = 0; j < n; ++j) {
        const int k = i + j;
        if (!p.matched[at + k] || (row == p.radius && k == p.radius)) continue;
        const float ex = float(p.x[at + k] - (p.source_x - p.radius + k)), ey = float(p.y[at + k] - y);
        const float product = p.window[row * side + k] * std::min(ex * ex + ey * ey, p.r_max2);
        acc[j] = acc[j] + product;
      }
    }
    if (lane_sum(acc) >= limit) return kInf;
  }
  return lane_sum(acc);
}

[[gnu::target("avx2")]] float patch_sum_avx2(const CoherencePatch& p, float limit) {
  alignas(32) float lanes[kLanes];
  const int side = 2 * p.radius + 1;
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256 r_max2 = _mm256_set1_ps(p.r_max2);
  __m256 acc = _mm256_setzero_ps();
  for (int row = p.row0; row <= p.row1; ++row) {
    const std::size_t at = p.first + std::size_t(row - p.row0) * p.pitch;  // column col0's index
    const __m256i y = _mm256_set1_epi32(p.source_y - p.radius + row);
    for (int i = p.col0; i <= p.col1; i += kLanes) {
      const int n = std::min(kLanes, p.col1 - i + 1);
      const std::size_t from = at + std::size_t(i - p.col0);
      const __m256i live = _mm256_cmpgt_epi32(_mm256_set1_epi32(n), lane);
      const __m256i mx = _mm256_maskload_epi32(p.x + from, live);
      const __m256i my = _mm256_maskload_epi32(p.y + from, live);
      const __m256 window = _mm256_maskload_ps(p.window + row * side + i, live);
      const __m256i flags = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(std::int64_t(matched_bytes(p.matched + from, n))));
      __m256i keep = _mm256_cmpgt_epi32(flags, _mm256_setzero_si256());
      if (row == p.radius)  // the centre is not its own neighbour
        keep = _mm256_andnot_si256(_mm256_cmpeq_epi32(lane, _mm256_set1_epi32(p.radius - i)), keep);
      const __m256i cx = _mm256_add_epi32(_mm256_set1_epi32(p.source_x - p.radius + i), lane);
      const __m256 ex = _mm256_cvtepi32_ps(_mm256_sub_epi32(mx, cx));
      const __m256 ey = _mm256_cvtepi32_ps(_mm256_sub_epi32(my, y));
      const __m256 d2 = _mm256_min_ps(_mm256_add_ps(_mm256_mul_ps(ex, ex), _mm256_mul_ps(ey, ey)), r_max2);
      acc = _mm256_add_ps(acc, _mm256_mul_ps(_mm256_and_ps(window, _mm256_castsi256_ps(keep)), d2));
    }
    if (limit < kInf) {
      _mm256_store_ps(lanes, acc);
      if (lane_sum(lanes) >= limit) return kInf;
    }
  }
  _mm256_store_ps(lanes, acc);
  return lane_sum(lanes);
}

// Target (tx, ty)'s window clipped to the field (source_x/y left at 0).
CoherencePatch clipped_patch(const CoherenceField& f, int tx, int ty) {
  const int r = f.radius;
  CoherencePatch p{f.x, f.y, f.matched, std::size_t(f.width)};
  p.row0 = std::max(0, r - ty), p.row1 = std::min(2 * r, r + f.height - 1 - ty);
  p.col0 = std::max(0, r - tx), p.col1 = std::min(2 * r, r + f.width - 1 - tx);
  p.first = std::size_t(ty - r + p.row0) * f.width + std::size_t(tx - r + p.col0);
  p.window = f.window, p.radius = r, p.r_max2 = f.r_max2;
  return p;
}

class SpatialCoherence final : public EnergyTerm {
 public:
  SpatialCoherence(float weight, float r_max) : weight_(weight), r_max2_(r_max * r_max) {}
  const char* name() const override { return "spatial_coherence"; }
  bool reads_field() const override { return true; }
  void prepare_row(const LevelContext& c, const OffsetField& field, int ty, PairCostBox* boxes) const override {
    if (windowed(c)) coherence_reach_row(view(c, field), ty, boxes);
  }
  float pair_cost(const LevelContext& c, const OffsetField& field, const PairCostBox& box, int tx, int ty, int sx,
                  int sy, float limit) const override {
    if (!windowed(c)) return weight_ * general_sum(c, field, tx, ty, sx, sy);
    // As coherence_patch_sum() ends for a sum of `box.outside`: infinity once it reaches the limit.
    if (!box.contains(sx, sy)) return box.outside >= limit / weight_ ? kInf : weight_ * box.outside;
    CoherencePatch p = clipped_patch(view(c, field), tx, ty);
    p.source_x = sx, p.source_y = sy;
    return weight_ * coherence_patch_sum(p, limit / weight_);
  }

 private:
  static bool windowed(const LevelContext& c) { return c.space->window && !c.space->rotated(); }

  CoherenceField view(const LevelContext& c, const OffsetField& field) const {
    return {field.x.data(), field.y.data(), c.constraints->matched().data(), field.width,
            field.height, c.space->window, c.space->radius, r_max2_};
  }

  // Rotated patches, or patches without a window, one neighbour at a time.
  float general_sum(const LevelContext& c, const OffsetField& field, int tx, int ty, int sx, int sy) const {
    const PatchSpace& s = *c.space;
    const int r = s.radius, side = 2 * r + 1;
    const float phi = s.rotated() ? s.rotation(sx, sy, tx, ty) : 0.0f;
    float sum = 0.0f;
    for (int dy = -r; dy <= r; ++dy) {
      const int ny = ty + dy;
      if (ny < 0 || ny >= field.height) continue;
      for (int dx = -r; dx <= r; ++dx) {
        const int nx = tx + dx;
        if (nx < 0 || nx >= field.width || (dx == 0 && dy == 0)) continue;
        const std::size_t ni = field.index(nx, ny);
        if (!c.constraints->matched()[ni]) continue;
        float ox = float(dx), oy = float(dy);
        if (phi != 0.0f) rotate_offset(phi, float(dx), float(dy), ox, oy);
        const float ex = float(field.x[ni]) - (float(sx) + ox), ey = float(field.y[ni]) - (float(sy) + oy);
        const float w = s.window ? s.window[(dy + r) * side + dx + r] : 1.0f;
        sum += w * std::min(ex * ex + ey * ey, r_max2_);
      }
    }
    return sum;
  }

  float weight_, r_max2_;
};

}  // namespace

float coherence_patch_sum(const CoherencePatch& patch, float limit, FixedKernel kernel) {
  static const bool avx2 = fixed_kernel_supported(FixedKernel::Avx2);
  if (kernel == FixedKernel::Avx2 || (kernel == FixedKernel::Best && avx2)) return patch_sum_avx2(patch, limit);
  return patch_sum_scalar(patch, limit);
}

namespace {

// t: the least whole distance whose square reaches the cap, so a source t
// or more columns (or rows) from every implied source is capped (ex * ex
// >= t * t >= r_max^2 in float, and adding ey * ey cannot lower it).
int capped_distance(float r_max2) {
  int t = int(std::ceil(std::sqrt(std::max(r_max2, 0.0f))));
  while (float(t) * float(t) < r_max2) ++t;
  while (t > 0 && float(t - 1) * float(t - 1) >= r_max2) --t;
  return t;
}

}  // namespace

PairCostBox coherence_reach(const CoherencePatch& p) {
  // The counted neighbours' implied sources M(p + d) - d: their box.
  int x0 = std::numeric_limits<int>::max(), y0 = x0, x1 = std::numeric_limits<int>::min(), y1 = x1;
  for (int row = p.row0; row <= p.row1; ++row) {
    const std::size_t at = p.first + std::size_t(row - p.row0) * p.pitch - std::size_t(p.col0);  // column 0's index
    for (int k = p.col0; k <= p.col1; ++k) {
      if (!p.matched[at + k] || (row == p.radius && k == p.radius)) continue;
      const int qx = p.x[at + k] - (k - p.radius), qy = p.y[at + k] - (row - p.radius);
      x0 = std::min(x0, qx), x1 = std::max(x1, qx), y0 = std::min(y0, qy), y1 = std::max(y1, qy);
    }
  }
  PairCostBox box;
  if (x0 > x1) {  // no neighbour counts: every source sums to nothing
    box.x0 = box.y0 = 1, box.x1 = box.y1 = 0;
    return box;
  }
  const int t = capped_distance(p.r_max2);
  box.x0 = x0 - t + 1, box.x1 = x1 + t - 1, box.y0 = y0 - t + 1, box.y1 = y1 + t - 1;
  CoherencePatch far = p;  // a source just outside the box: every neighbour capped
  far.source_x = x0 - t, far.source_y = y0 - t;
  box.outside = coherence_patch_sum(far);
  return box;
}

namespace {

// The capped sum of a whole window whose neighbours all count: that of every
// target inside the field whose window is all matched (the same products
// in the same lanes whatever the matches).
float full_window_capped(const CoherenceField& f) {
  const int side = 2 * f.radius + 1;
  const std::vector<std::int32_t> zero(std::size_t(side) * side, 0);
  const std::vector<std::uint8_t> all(std::size_t(side) * side, 1);
  CoherencePatch p{zero.data(), zero.data(), all.data(), std::size_t(side)};
  p.row0 = p.col0 = 0, p.row1 = p.col1 = side - 1;
  p.window = f.window, p.radius = f.radius, p.r_max2 = f.r_max2;
  return coherence_reach(p).outside;
}

}  // namespace

void coherence_reach_row(const CoherenceField& f, int ty, PairCostBox* boxes) {
  const int r = f.radius, w = f.width, side = 2 * r + 1;
  const int y0 = std::max(0, ty - r), y1 = std::min(f.height - 1, ty + r);
  constexpr int kBig = std::numeric_limits<int>::max(), kSmall = std::numeric_limits<int>::min();
  // Per column x (at x + r: r columns of padding either side), over the
  // window's rows: the offsets' minima and maxima among matched pixels and
  // how many are matched; then the same over each target's 2r + 1 columns.
  const std::size_t n = std::size_t(w) + 2 * r;
  thread_local std::vector<int> scratch;
  scratch.resize(10 * n);
  int *lx = scratch.data(), *hx = lx + n, *ly = hx + n, *hy = ly + n, *count = hy + n;
  int *wlx = count + n, *whx = wlx + n, *wly = whx + n, *why = wly + n, *wcount = why + n;
  std::fill_n(lx, n, kBig), std::fill_n(hx, n, kSmall), std::fill_n(ly, n, kBig), std::fill_n(hy, n, kSmall);
  std::fill_n(count, n, 0);
  for (int y = y0; y <= y1; ++y) {
    const std::size_t row = std::size_t(y) * w;
    const std::int32_t *mx = f.x + row, *my = f.y + row;
    const std::uint8_t* m = f.matched + row;
    for (int x = 0; x < w; ++x) {
      const int ox = mx[x] - x, oy = my[x] - y, k = x + r;
      const bool on = m[x] != 0;
      lx[k] = on ? std::min(lx[k], ox) : lx[k], hx[k] = on ? std::max(hx[k], ox) : hx[k];
      ly[k] = on ? std::min(ly[k], oy) : ly[k], hy[k] = on ? std::max(hy[k], oy) : hy[k];
      count[k] += on;
    }
  }
  std::copy_n(lx, w, wlx), std::copy_n(hx, w, whx), std::copy_n(ly, w, wly), std::copy_n(hy, w, why);
  std::copy_n(count, w, wcount);
  for (int c = 1; c < side; ++c)
    for (int x = 0; x < w; ++x) {
      wlx[x] = std::min(wlx[x], lx[x + c]), whx[x] = std::max(whx[x], hx[x + c]);
      wly[x] = std::min(wly[x], ly[x + c]), why[x] = std::max(why[x], hy[x + c]);
      wcount[x] += count[x + c];
    }
  const bool rows_inside = y0 == ty - r && y1 == ty + r;
  const float full = rows_inside ? full_window_capped(f) : 0.0f;
  const int t = capped_distance(f.r_max2);
  for (int tx = 0; tx < w; ++tx) {
    PairCostBox& box = boxes[tx];
    if (rows_inside && tx >= r && tx + r < w && wcount[tx] == side * side) {
      box.x0 = tx + wlx[tx] - t + 1, box.x1 = tx + whx[tx] + t - 1;
      box.y0 = ty + wly[tx] - t + 1, box.y1 = ty + why[tx] + t - 1;
      box.outside = full;
      continue;
    }
    box = coherence_reach(clipped_patch(f, tx, ty));
  }
}

std::shared_ptr<const EnergyTerm> make_spatial_coherence(float weight, float r_max) {
  return std::make_shared<SpatialCoherence>(weight, r_max);
}

}  // namespace tempera

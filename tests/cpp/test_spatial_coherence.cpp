// The spatial coherence term's neighbour sum (Bénard et al. 2013, eq. 5):
// the AVX2 kernel equals the scalar one to the bit, both equal the sum
// written out neighbour by neighbour, and both stop only once it reaches the
// limit; sources no neighbour's match reaches need no sum.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "tempera/engine/spatial_coherence.hpp"

namespace tempera {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

struct Field {
  int width, height;
  std::vector<std::int32_t> x, y;
  std::vector<std::uint8_t> matched;
};

Field random_field(int w, int h, unsigned seed) {
  Field f{w, h, std::vector<std::int32_t>(std::size_t(w) * h), std::vector<std::int32_t>(std::size_t(w) * h),
          std::vector<std::uint8_t>(std::size_t(w) * h)};
  std::mt19937 rng(seed);
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      const std::size_t i = std::size_t(py) * w + px;
      // Mostly one coherent piece (source = target + (7, 3)), some pixels off
      // by a little or a lot, some not matched.
      const int kind = int(rng() % 10);
      f.x[i] = px + 7 + (kind == 0 ? int(rng() % 5) - 2 : kind == 1 ? int(rng() % 200) : 0);
      f.y[i] = py + 3 + (kind == 0 ? int(rng() % 5) - 2 : 0);
      f.matched[i] = kind != 2;
    }
  return f;
}

std::vector<float> gaussian_window(int r) {
  std::vector<float> w;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) w.push_back(std::exp(-0.5f * float(dx * dx + dy * dy) / float(r * r)));
  return w;
}

double written_out(const Field& f, const std::vector<float>& window, int r, float r_max2, int tx, int ty, int sx,
                   int sy) {
  double sum = 0.0;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      if (tx + dx < 0 || ty + dy < 0 || tx + dx >= f.width || ty + dy >= f.height) continue;
      const std::size_t i = std::size_t(ty + dy) * f.width + tx + dx;
      if ((dx == 0 && dy == 0) || !f.matched[i]) continue;
      const double ex = f.x[i] - (sx + dx), ey = f.y[i] - (sy + dy);
      sum += window[std::size_t((dy + r) * (2 * r + 1) + dx + r)] * std::min(ex * ex + ey * ey, double(r_max2));
    }
  return sum;
}

TEST(SpatialCoherence, KernelsAgreeToTheBitAndWithTheSumWrittenOut) {
  const Field f = random_field(40, 30, 5);
  for (int r : {1, 2, 4, 5}) {  // rows of up to 3, 5, 9 and 11 neighbours: one or two lane groups
    const std::vector<float> window = gaussian_window(r);
    int compared = 0;
    for (int ty = 0; ty < f.height; ty += 3)  // patches inside the field and clipped by its border
      for (int tx = 0; tx < f.width; tx += 2)
        for (const auto [sx, sy] : {std::pair{tx + 7, ty + 3}, std::pair{tx + 8, ty + 3}, std::pair{tx + 90, ty}}) {
          CoherencePatch p{f.x.data(), f.y.data(), f.matched.data(), std::size_t(f.width)};
          p.row0 = std::max(0, r - ty), p.row1 = std::min(2 * r, r + f.height - 1 - ty);
          p.col0 = std::max(0, r - tx), p.col1 = std::min(2 * r, r + f.width - 1 - tx);
          p.first = std::size_t(ty - r + p.row0) * f.width + std::size_t(tx - r + p.col0);
          p.window = window.data(), p.radius = r, p.source_x = sx, p.source_y = sy, p.r_max2 = 9.0f;
          const float scalar = coherence_patch_sum(p, kInf, FixedKernel::Scalar);
          ASSERT_NEAR(scalar, written_out(f, window, r, 9.0f, tx, ty, sx, sy), 1e-4 * (1.0 + scalar));
          for (const FixedKernel k : {FixedKernel::Scalar, FixedKernel::Avx2}) {
            if (!fixed_kernel_supported(k)) continue;
            ASSERT_EQ(scalar, coherence_patch_sum(p, kInf, k)) << r << " " << tx << " " << ty;
            // A limit above the sum: the whole sum; at or below it: infinity.
            ASSERT_EQ(scalar, coherence_patch_sum(p, scalar * 1.001f + 1e-3f, k));
            if (scalar > 0) ASSERT_EQ(kInf, coherence_patch_sum(p, scalar, k));
            if (scalar > 0) ASSERT_EQ(kInf, coherence_patch_sum(p, scalar * 0.5f, k));
          }
          ++compared;
        }
    EXPECT_GT(compared, 50);
  }
}

// coherence_reach(): every source outside its box sums to `outside` to the
// bit in both kernels, every implied source M(p + d) - d is inside it, and
// the box is not the whole exemplar (most far sources are outside it).
TEST(SpatialCoherence, SourcesOutsideTheReachSumToTheCappedValue) {
  const Field f = random_field(40, 30, 7);
  for (int r : {1, 2, 4}) {
    const std::vector<float> window = gaussian_window(r);
    for (const float r_max2 : {9.0f, 6.25f, 2.0f, 0.0f}) {
      int outside = 0, inside = 0;
      for (int ty = 0; ty < f.height; ty += 3)
        for (int tx = 0; tx < f.width; tx += 2) {
          CoherencePatch p{f.x.data(), f.y.data(), f.matched.data(), std::size_t(f.width)};
          p.row0 = std::max(0, r - ty), p.row1 = std::min(2 * r, r + f.height - 1 - ty);
          p.col0 = std::max(0, r - tx), p.col1 = std::min(2 * r, r + f.width - 1 - tx);
          p.first = std::size_t(ty - r + p.row0) * f.width + std::size_t(tx - r + p.col0);
          p.window = window.data(), p.radius = r, p.r_max2 = r_max2;
          const PairCostBox box = coherence_reach(p);
          for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx) {
              const int nx = tx + dx, ny = ty + dy;
              if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= f.width || ny >= f.height) continue;
              const std::size_t i = std::size_t(ny) * f.width + nx;
              if (f.matched[i] && r_max2 > 0) {
                ASSERT_TRUE(box.contains(f.x[i] - dx, f.y[i] - dy));
              }
            }
          for (int sy = ty + 3 - 9; sy <= ty + 3 + 9; sy += 3)
            for (int sx = tx + 7 - 240; sx <= tx + 7 + 240; sx += 5) {
              p.source_x = sx, p.source_y = sy;
              if (box.contains(sx, sy)) {
                ++inside;
                continue;
              }
              ++outside;
              for (const FixedKernel k : {FixedKernel::Scalar, FixedKernel::Avx2}) {
                if (fixed_kernel_supported(k)) {
                  ASSERT_EQ(box.outside, coherence_patch_sum(p, kInf, k));
                }
              }
            }
        }
      EXPECT_GT(outside, 2 * inside) << r << " " << r_max2;
      if (r_max2 > 0) {
        EXPECT_GT(inside, 0) << r << " " << r_max2;
      }
    }
  }
}

// coherence_reach_row(): each target's box holds coherence_reach()'s (it may
// be wider, never narrower) and its `outside` is the same to the bit, inside
// the field, at its borders and around unmatched pixels.
TEST(SpatialCoherence, TheRowsBoxesHoldEachTargetsReach) {
  for (const unsigned seed : {3u, 11u}) {
    Field f = random_field(37, 23, seed);
    if (seed == 11u) std::fill(f.matched.begin(), f.matched.end(), std::uint8_t(1));  // every window whole
    for (int r : {1, 2, 4}) {
      const std::vector<float> window = gaussian_window(r);
      const CoherenceField field{f.x.data(), f.y.data(), f.matched.data(), f.width, f.height, window.data(), r, 9.0f};
      std::vector<PairCostBox> row(std::size_t(f.width));
      int wider = 0;
      for (int ty = 0; ty < f.height; ++ty) {
        coherence_reach_row(field, ty, row.data());
        for (int tx = 0; tx < f.width; ++tx) {
          CoherencePatch p{f.x.data(), f.y.data(), f.matched.data(), std::size_t(f.width)};
          p.row0 = std::max(0, r - ty), p.row1 = std::min(2 * r, r + f.height - 1 - ty);
          p.col0 = std::max(0, r - tx), p.col1 = std::min(2 * r, r + f.width - 1 - tx);
          p.first = std::size_t(ty - r + p.row0) * f.width + std::size_t(tx - r + p.col0);
          p.window = window.data(), p.radius = r, p.r_max2 = 9.0f;
          const PairCostBox exact = coherence_reach(p), got = row[std::size_t(tx)];
          ASSERT_EQ(exact.outside, got.outside) << seed << " " << r << " " << tx << " " << ty;
          if (exact.x0 > exact.x1) continue;  // no neighbour counts: nothing to hold
          ASSERT_TRUE(got.x0 <= exact.x0 && got.x1 >= exact.x1 && got.y0 <= exact.y0 && got.y1 >= exact.y1)
              << seed << " " << r << " " << tx << " " << ty;
          wider += got.x0 < exact.x0 || got.x1 > exact.x1 || got.y0 < exact.y0 || got.y1 > exact.y1;
        }
      }
      if (seed == 11u) {
        EXPECT_GT(wider, 0) << r;  // the row's own boxes were taken (they count the centre)
      }
    }
  }
}

}  // namespace
}  // namespace tempera

#include "tempera/engine/weighted_mode.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cmath>

#include "tempera/engine/error.hpp"

namespace tempera {

// The mode was the whole cost of a Color Me Noisy frame (93%: 49^2 kernels a
// pixel at first), so it is computed without changing the answer:
//  - equal colours (neighbouring patches of a coherent field copy the same
//    source pixel) are scored once, with their count as weight;
//  - each pair's kernel is evaluated once, for both ends;
//  - a kernel below half a float step of 1 counts as 0: every score starts at
//    its own count (>= 1), so adding it could not change the sum.
// Every score is its count plus count(k) * kernel(j, k) over k in ascending
// order (a skipped kernel adds an exact 0), in both variants: the AVX2 one
// sums eight scores at once in the same order, so their floats are the same.

namespace {

constexpr float kNegligible = 17.5f;  // exp(-17.5) < 2^-25
constexpr std::size_t kLanes = 8;

std::size_t round_up(std::size_t n) { return (n + kLanes - 1) / kLanes * kLanes; }

// The kernel of two colours whose squared distance over h^2 is x.
inline float kernel_of(float x) { return x > kNegligible ? 0.0f : std::exp(-x); }

std::size_t first_best(const ModeScratch& m, std::size_t u) {
  std::size_t best = 0;
  for (std::size_t j = 1; j < u; ++j)
    if (m.score[j] > m.score[best]) best = j;
  return m.first[best];
}

// Appends candidate j of `c` to the unique colours, or counts it again.
inline void add_unique(const ModeCandidates& c, std::size_t j, std::size_t found, ModeScratch& m) {
  if (found < m.unique.size()) {
    m.count[found] += 1.0f;
    return;
  }
  float v[64];
  c.copy(j, v);
  m.unique.push(v);
  m.count.push_back(1.0f);
  m.first.push_back(std::uint32_t(j));
}

void start(const ModeCandidates& c, ModeScratch& m) {
  if (c.channels() > 64) throw ValueError("the weighted mode takes at most 64 channels");
  m.unique.reset(c.channels(), c.size());
  m.count.clear(), m.first.clear();
}

std::size_t mode_scalar(const ModeCandidates& c, float inv, ModeScratch& m) {
  start(c, m);
  const int channels = c.channels();
  for (std::size_t j = 0; j < c.size(); ++j) {
    std::size_t u = 0;
    for (; u < m.unique.size(); ++u) {
      int ch = 0;
      while (ch < channels && c.plane(ch)[j] == m.unique.plane(ch)[u]) ++ch;
      if (ch == channels) break;
    }
    add_unique(c, j, u, m);
  }
  const std::size_t u = m.unique.size();
  m.score.assign(m.count.begin(), m.count.end());
  for (std::size_t j = 0; j < u; ++j)
    for (std::size_t k = j + 1; k < u; ++k) {
      float d = 0.0f;
      for (int ch = 0; ch < channels; ++ch) {
        const float e = m.unique.plane(ch)[j] - m.unique.plane(ch)[k];
        d += e * e;
      }
      const float kernel = kernel_of(d * inv);
      m.score[j] += m.count[k] * kernel;
      m.score[k] += m.count[j] * kernel;
    }
  return first_best(m, u);
}

[[gnu::target("avx2")]] std::size_t mode_avx2(const ModeCandidates& c, float inv, ModeScratch& m) {
  start(c, m);
  const int channels = c.channels();
  for (std::size_t j = 0; j < c.size(); ++j) {
    std::size_t found = m.unique.size();
    for (std::size_t b = 0; b < m.unique.size(); b += kLanes) {
      __m256 equal = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
      for (int ch = 0; ch < channels; ++ch)
        equal = _mm256_and_ps(equal, _mm256_cmp_ps(_mm256_loadu_ps(m.unique.plane(ch) + b),
                                                   _mm256_set1_ps(c.plane(ch)[j]), _CMP_EQ_OQ));
      const std::size_t valid = std::min(kLanes, m.unique.size() - b);
      const unsigned bits = unsigned(_mm256_movemask_ps(equal)) & ((1u << valid) - 1u);
      if (bits) {
        found = b + std::size_t(__builtin_ctz(bits));
        break;
      }
    }
    add_unique(c, j, found, m);
  }
  // The kernel of every pair, both ways (row j, column k), 0 on the diagonal.
  const std::size_t u = m.unique.size(), row = round_up(u);
  m.kernel.assign(u * row, 0.0f);
  const __m256 scale = _mm256_set1_ps(inv);
  alignas(32) float x[kLanes];
  for (std::size_t j = 0; j < u; ++j)
    for (std::size_t k = j + 1; k < u; k += kLanes) {
      __m256 d = _mm256_setzero_ps();
      for (int ch = 0; ch < channels; ++ch) {
        const __m256 e =
            _mm256_sub_ps(_mm256_set1_ps(m.unique.plane(ch)[j]), _mm256_loadu_ps(m.unique.plane(ch) + k));
        d = _mm256_add_ps(d, _mm256_mul_ps(e, e));
      }
      _mm256_store_ps(x, _mm256_mul_ps(d, scale));
      for (std::size_t l = 0; l < kLanes && k + l < u; ++l)
        m.kernel[j * row + k + l] = m.kernel[(k + l) * row + j] = kernel_of(x[l]);
    }
  // Eight scores at a time, each summed over k in ascending order.
  m.score.resize(row);
  m.count.resize(row, 0.0f);
  for (std::size_t b = 0; b < u; b += kLanes) {
    __m256 s = _mm256_loadu_ps(m.count.data() + b);
    for (std::size_t k = 0; k < u; ++k)
      s = _mm256_add_ps(s, _mm256_mul_ps(_mm256_set1_ps(m.count[k]), _mm256_loadu_ps(m.kernel.data() + k * row + b)));
    _mm256_storeu_ps(m.score.data() + b, s);
  }
  return first_best(m, u);
}

}  // namespace

void ModeCandidates::reset(int channels, std::size_t capacity) {
  channels_ = channels;
  stride_ = round_up(capacity) + kLanes;  // a load of eight from any candidate stays inside
  if (planes_.size() < std::size_t(channels) * stride_) planes_.resize(std::size_t(channels) * stride_);
  n_ = 0;
}

std::size_t weighted_mode(const ModeCandidates& candidates, float bandwidth, ModeScratch& scratch,
                          FixedKernel kernel) {
  if (candidates.size() == 0) throw ValueError("the weighted mode of no candidates");
  if (kernel != FixedKernel::Best && !fixed_kernel_supported(kernel))
    throw ValueError("the weighted mode's kernel is not supported by this CPU");
  static const bool has_avx2 = fixed_kernel_supported(FixedKernel::Avx2);  // asked once: a call per pixel
  const float inv = 1.0f / (bandwidth * bandwidth);
  const bool avx2 = kernel == FixedKernel::Best ? has_avx2 : kernel != FixedKernel::Scalar;
  return avx2 ? mode_avx2(candidates, inv, scratch) : mode_scalar(candidates, inv, scratch);
}

}  // namespace tempera

#include "tempera/engine/weighted_mode.hpp"

#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cmath>

#include "tempera/engine/error.hpp"

namespace tempera {

// The mode was the whole cost of a Color Me Noisy frame (93%: 49^2 kernels a
// pixel at first), so it is computed without changing the answer:
//  - equal colours (neighbouring patches of a coherent field copy the same
//    source pixel) are scored once, with their count as weight;
//  - a kernel below half a float step of 1 counts as 0: every score starts at
//    its own count (>= 1), so adding it could not change the sum.
// Every score is its count plus count(k) * kernel(j, k) over k != j in
// ascending order (a skipped kernel adds an exact 0), in both variants: the
// AVX2 one sums eight scores at once in the same order, with the same floats.
// The kernel is the engine's own exp (exp_neg below), not the C library's,
// so that eight are evaluated at once and every CPU and C library gives the
// same frames.

namespace {

constexpr float kNegligible = 17.5f;  // exp(-17.5) < 2^-25
constexpr std::size_t kLanes = 8;

std::size_t round_up(std::size_t n) { return (n + kLanes - 1) / kLanes * kLanes; }

// exp(-x) for 0 <= x <= kNegligible, within about 2 float steps (measured in
// the test): e^-x = 2^-n e^r with n the integer nearest x / ln 2 and
// r = n ln 2 - x in [-ln 2 / 2, ln 2 / 2] (ln 2 split in two so that n ln 2
// keeps its bits), e^r by its Taylor series to r^7 (the rest below 0.1 of a
// float step). Both variants round and multiply the same floats in the same
// order (the build has no FMA contraction: x86-64-v2, and the AVX2 target
// does not include FMA).
constexpr float kLog2e = 1.44269504f;
constexpr float kLn2Hi = 0.693359375f;  // 9 significant bits: n * kLn2Hi is exact for n < 2^15
constexpr float kLn2Lo = float(0.69314718055994531 - 0.693359375);
constexpr float kTaylor[8] = {1.0f, 1.0f, 1.0f / 2, 1.0f / 6, 1.0f / 24, 1.0f / 120, 1.0f / 720, 1.0f / 5040};

float exp_neg(float x) {
  const float n = std::nearbyint(x * kLog2e);
  const float r = (n * kLn2Hi - x) + n * kLn2Lo;
  float p = kTaylor[7];
  for (int k = 6; k >= 0; --k) p = p * r + kTaylor[k];
  return p * std::bit_cast<float>((127 - int(n)) << 23);
}

[[gnu::target("avx2")]] inline __m256 exp_neg(__m256 x) {
  const __m256 n = _mm256_round_ps(_mm256_mul_ps(x, _mm256_set1_ps(kLog2e)), _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  const __m256 r = _mm256_add_ps(_mm256_sub_ps(_mm256_mul_ps(n, _mm256_set1_ps(kLn2Hi)), x),
                                 _mm256_mul_ps(n, _mm256_set1_ps(kLn2Lo)));
  __m256 p = _mm256_set1_ps(kTaylor[7]);
  for (int k = 6; k >= 0; --k) p = _mm256_add_ps(_mm256_mul_ps(p, r), _mm256_set1_ps(kTaylor[k]));
  const __m256i scale = _mm256_slli_epi32(_mm256_sub_epi32(_mm256_set1_epi32(127), _mm256_cvtps_epi32(n)), 23);
  return _mm256_mul_ps(p, _mm256_castsi256_ps(scale));
}

std::size_t first_best(const ModeScratch& m, std::size_t u) {
  std::size_t best = 0;
  for (std::size_t j = 1; j < u; ++j)
    if (m.score[j] > m.score[best]) best = j;
  return m.first[best];
}

inline bool same_colour(const ModeCandidates& c, std::size_t a, std::size_t b) {
  for (int ch = 0; ch < c.channels(); ++ch)
    if (!(c.plane(ch)[a] == c.plane(ch)[b])) return false;
  return true;
}

// Appends candidate j of `c` to the unique colours, or counts it again.
inline void add_unique(const ModeCandidates& c, std::size_t j, std::size_t found, ModeScratch& m) {
  if (found < m.unique.size()) {
    m.count[found] += 1.0f;
    return;
  }
  m.unique.push(c, j);
  m.count.push_back(1.0f);
  m.first.push_back(std::uint32_t(j));
}

void start(const ModeCandidates& c, ModeScratch& m) {
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
    for (std::size_t k = j + 1; k < u; ++k) {  // each pair's kernel once, for both ends
      float d = 0.0f;
      for (int ch = 0; ch < channels; ++ch) {
        const float e = m.unique.plane(ch)[j] - m.unique.plane(ch)[k];
        d += e * e;
      }
      const float kernel = mode_kernel(d * inv);
      m.score[j] += m.count[k] * kernel;
      m.score[k] += m.count[j] * kernel;
    }
  return first_best(m, u);
}

// The 8 x 8 floats at `from` (rows `pitch` apart), transposed to `to`.
[[gnu::target("avx2")]] void transpose8(const float* from, float* to, std::size_t pitch) {
  __m256 r[8], t[8], q[8];
  for (int i = 0; i < 8; ++i) r[i] = _mm256_loadu_ps(from + std::size_t(i) * pitch);
  for (int i = 0; i < 8; i += 2) {  // t[i], t[i + 1]: rows i, i + 1 interleaved
    t[i] = _mm256_unpacklo_ps(r[i], r[i + 1]);
    t[i + 1] = _mm256_unpackhi_ps(r[i], r[i + 1]);
  }
  for (int i = 0; i < 8; i += 4) {  // q: four rows' values of one column per 128-bit half
    q[i] = _mm256_shuffle_ps(t[i], t[i + 2], 0x44);
    q[i + 1] = _mm256_shuffle_ps(t[i], t[i + 2], 0xEE);
    q[i + 2] = _mm256_shuffle_ps(t[i + 1], t[i + 3], 0x44);
    q[i + 3] = _mm256_shuffle_ps(t[i + 1], t[i + 3], 0xEE);
  }
  for (int i = 0; i < 4; ++i) {
    _mm256_storeu_ps(to + std::size_t(i) * pitch, _mm256_permute2f128_ps(q[i], q[i + 4], 0x20));
    _mm256_storeu_ps(to + std::size_t(i + 4) * pitch, _mm256_permute2f128_ps(q[i], q[i + 4], 0x31));
  }
}

// m.kernel[k * w + j] = the kernel of colours j and k (0 for j = k and where
// negligible), w = u rounded up to 8. Eight j at a time for each k >= j's
// block; the blocks of 8 x 8 above those are the transposes of their mirrors
// (the kernel of (j, k) is that of (k, j) bit for bit: the same squares), so
// a pair's exp is evaluated once but within the diagonal's blocks.
[[gnu::target("avx2")]] void pair_kernels(ModeScratch& m, float inv) {
  const std::size_t u = m.unique.size(), w = round_up(u);
  const int channels = m.unique.channels();
  m.kernel.resize(w * w);
  const __m256 scale = _mm256_set1_ps(inv), negligible = _mm256_set1_ps(kNegligible);
  for (std::size_t b = 0; b < u; b += kLanes) {
    const __m256i lane = _mm256_add_epi32(_mm256_set1_epi32(int(b)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    for (std::size_t k = 0; k < u; ++k) {
      if (k < b) continue;  // a block above the diagonal: the mirror's transpose
      __m256 d = _mm256_setzero_ps();
      for (int ch = 0; ch < channels; ++ch) {
        const __m256 e =
            _mm256_sub_ps(_mm256_loadu_ps(m.unique.plane(ch) + b), _mm256_set1_ps(m.unique.plane(ch)[k]));
        d = _mm256_add_ps(d, _mm256_mul_ps(e, e));
      }
      const __m256 x = _mm256_mul_ps(d, scale);
      const __m256 other = _mm256_castsi256_ps(
          _mm256_xor_si256(_mm256_cmpeq_epi32(lane, _mm256_set1_epi32(int(k))), _mm256_set1_epi32(-1)));
      const __m256 keep = _mm256_and_ps(_mm256_cmp_ps(x, negligible, _CMP_LE_OQ), other);
      _mm256_storeu_ps(m.kernel.data() + k * w + b, _mm256_and_ps(exp_neg(_mm256_min_ps(x, negligible)), keep));
    }
  }
  // Rows c..c+7 of a later block column b from rows b..b+7 of block column c
  // (rows from u on are not computed: they land in lanes from u on, whose
  // scores are never read).
  for (std::size_t c = 0; c < u; c += kLanes)
    for (std::size_t b = c + kLanes; b < u; b += kLanes)
      transpose8(m.kernel.data() + b * w + c, m.kernel.data() + c * w + b, w);
}

[[gnu::target("avx2")]] std::size_t mode_avx2(const ModeCandidates& c, float inv, ModeScratch& m) {
  start(c, m);
  const int channels = c.channels();
  std::size_t previous = 0;  // the unique colour of candidate j - 1
  for (std::size_t j = 0; j < c.size(); ++j) {
    // Along a coherent field, neighbouring patches bring the same source
    // pixel one after the other: then the scan would find the same colour.
    if (j > 0 && same_colour(c, j, j - 1)) {
      m.count[previous] += 1.0f;
      continue;
    }
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
    previous = std::min(found, m.unique.size() - 1);
  }
  // Scores j .. j + 7 at once, each summed over k in ascending order, from
  // the pair kernels (pair_kernels above).
  const std::size_t u = m.unique.size(), w = round_up(u);
  m.score.resize(w);
  m.count.resize(w, 0.0f);
  pair_kernels(m, inv);
  for (std::size_t b = 0; b < u; b += kLanes) {
    __m256 s = _mm256_loadu_ps(m.count.data() + b);
    for (std::size_t k = 0; k < u; ++k)
      s = _mm256_add_ps(s, _mm256_mul_ps(_mm256_set1_ps(m.count[k]), _mm256_loadu_ps(m.kernel.data() + k * w + b)));
    _mm256_storeu_ps(m.score.data() + b, s);
  }
  return first_best(m, u);
}

}  // namespace

float mode_kernel(float x) { return x <= kNegligible ? exp_neg(x) : 0.0f; }

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

#include "tempera/engine/patch_distance.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "tempera/engine/error.hpp"

namespace tempera {

FeatureImage::FeatureImage(int w, int h, int channels)
    : width(w), height(h), stride(channels), data(std::size_t(w) * h * channels, 0.0f) {}

FeatureImage FeatureImage::fixed_point(int w, int h, int channels, const std::vector<float>& channel_offset,
                                       float quant_step, int max_value) {
  FeatureImage f;
  f.width = w, f.height = h, f.stride = channels;
  f.use_fixed_point(channel_offset, quant_step, max_value);
  return f;
}

float FeatureImage::code(std::size_t slot, float v) const {
  return std::clamp(std::nearbyint((v - offset[slot]) / step), 0.0f, float(fixed_max));
}

// Switches to fixed-point storage, every slot holding the code of 0.
void FeatureImage::use_fixed_point(const std::vector<float>& channel_offset, float quant_step, int max_value) {
  if (int(channel_offset.size()) != stride || !(quant_step > 0.0f) || quantized() ||
      (max_value != kFixed12 && max_value != kFixed8))
    throw ValueError("internal: bad feature quantization");
  offset = channel_offset;
  step = quant_step;
  fixed_max = max_value;
  const std::size_t n = std::size_t(width) * height * stride;
  if (bytes())
    fixed8.resize(n);
  else
    fixed.resize(n);
  for (std::size_t i = 0; i < std::size_t(stride); ++i) {
    if (code(i, 0.0f) == 0.0f) continue;  // resize zeroed it already
    for (std::size_t j = i; j < n; j += std::size_t(stride)) store(j, 0.0f);
  }
}

void FeatureImage::store(std::size_t i, float v) {
  const float q = code(i % std::size_t(stride), v);
  if (bytes())
    fixed8[i] = std::uint8_t(q);
  else
    fixed[i] = std::int16_t(q);
}

void FeatureImage::set_channels(int first, const ImageView& image, float scale) {
  set_channels(first, image, std::vector<float>(std::size_t(std::max(0, image.channels)), scale));
}

void FeatureImage::set_channels(int first, const ImageView& image, const std::vector<float>& scales) {
  if (image.width != width || image.height != height || first + image.channels > stride ||
      int(scales.size()) != image.channels)
    throw ValueError("internal: feature channels do not fit the feature image");
  const std::size_t n = std::size_t(width) * height;
  if (quantized()) {
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < image.channels; ++c) store(i * stride + first + c, image.data[i * image.channels + c] * scales[c]);
    return;
  }
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < image.channels; ++c)
      data[i * stride + first + c] = image.data[i * image.channels + c] * scales[c];
}

void FeatureImage::set_channels(const std::vector<ChannelWrite>& writes) {
  for (const ChannelWrite& w : writes) set_channels(w.first, w.image, w.scales);
}

void FeatureImage::zero_channels(int first, int count) {
  const std::size_t n = std::size_t(width) * height;
  for (std::size_t i = 0; i < n; ++i)
    for (int c = first; c < first + count; ++c) {
      if (quantized())
        store(i * stride + c, 0.0f);
      else
        data[i * stride + c] = 0.0f;
    }
}

void FeatureImage::quantize(const std::vector<float>& channel_offset, float quant_step, int max_value) {
  use_fixed_point(channel_offset, quant_step, max_value);
  for (std::size_t i = 0; i < data.size(); ++i) store(i, data[i]);
  std::vector<float>().swap(data);
}

namespace {

// Per-slot minimum and maximum of feature values.
struct SlotRange {
  std::vector<float> lo, hi;
  explicit SlotRange(int stride)
      : lo(std::size_t(stride), std::numeric_limits<float>::infinity()),
        hi(std::size_t(stride), -std::numeric_limits<float>::infinity()) {}
  void add(std::size_t slot, float v) {
    lo[slot] = std::min(lo[slot], v);
    hi[slot] = std::max(hi[slot], v);
  }
  // The per-slot minimum as offsets, the widest slot's range / max_value as the step.
  void to_fixed_point(int max_value, std::vector<float>& offset, float& step) {
    float range = 0.0f;
    for (std::size_t c = 0; c < lo.size(); ++c) {
      if (!(lo[c] <= hi[c])) lo[c] = hi[c] = 0.0f;
      range = std::max(range, hi[c] - lo[c]);
    }
    offset = lo;
    // A flat feature set still needs a positive step.
    step = range > 0.0f ? range / float(max_value) : 1.0f;
  }
};

// Adds the final values of slots [first_slot, stride) that `writes` leave.
void add_writes(SlotRange& range, const std::vector<ChannelWrite>& writes, int stride, int first_slot) {
  std::vector<int> last(std::size_t(stride), -1);  // per slot: the write that sets it last
  for (std::size_t k = 0; k < writes.size(); ++k)
    for (int c = 0; c < writes[k].image.channels; ++c)
      if (writes[k].first + c >= first_slot) last[std::size_t(writes[k].first + c)] = int(k);
  for (int slot = first_slot; slot < stride; ++slot)
    if (last[std::size_t(slot)] < 0) range.add(std::size_t(slot), 0.0f);  // never written: 0, as allocated
  for (std::size_t k = 0; k < writes.size(); ++k) {
    const ChannelWrite& w = writes[k];
    if (w.first + w.image.channels > stride || int(w.scales.size()) != w.image.channels)
      throw ValueError("internal: feature channels do not fit the feature image");
    std::vector<std::size_t> kept;  // channels of this write that are final
    for (int c = 0; c < w.image.channels; ++c)
      if (w.first + c >= first_slot && last[std::size_t(w.first + c)] == int(k)) kept.push_back(std::size_t(c));
    const std::size_t n = w.image.pixel_count(), channels = std::size_t(w.image.channels);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t c : kept) range.add(std::size_t(w.first) + c, w.image.data[i * channels + c] * w.scales[c]);
  }
}

}  // namespace

void fixed_point_range(const FeatureImage& source, const FeatureImage& target, int target_first, int max_value,
                       std::vector<float>& offset, float& step) {
  const int stride = source.stride;
  if (target.stride != stride) throw ValueError("internal: feature strides differ");
  SlotRange range(stride);
  auto extend = [&](const FeatureImage& f, int first) {
    for (std::size_t i = 0; i < f.data.size(); i += std::size_t(stride))
      for (int c = first; c < stride; ++c) range.add(std::size_t(c), f.data[i + std::size_t(c)]);
  };
  extend(source, 0);
  extend(target, target_first);
  range.to_fixed_point(max_value, offset, step);
}

void fixed_point_range(const std::vector<ChannelWrite>& source, const std::vector<ChannelWrite>& target, int stride,
                       int target_first, int max_value, std::vector<float>& offset, float& step) {
  SlotRange range(stride);
  add_writes(range, source, stride, 0);
  add_writes(range, target, stride, target_first);
  range.to_fixed_point(max_value, offset, step);
}

// Fixed-point SSD kernels. Values are at most 12 bits, so a difference fits
// int16 and a madd pair (2 * 4095^2) an int32 lane; blocks of kBlock values
// keep a lane below 2^31 before it is summed into int64. All kernels add the
// same integers, so they agree exactly.
namespace {

constexpr int kBlock = 1024;

template <class T>
std::int64_t fixed_ssd_scalar(const T* a, const T* b, int n) {
  std::int64_t sum = 0;
  for (int i = 0; i < n; ++i) {
    const std::int32_t d = std::int32_t(a[i]) - b[i];
    sum += d * d;
  }
  return sum;
}

[[gnu::target("avx2")]] std::int64_t hsum_epi32(__m256i v) {
  const __m256i lo = _mm256_cvtepi32_epi64(_mm256_castsi256_si128(v));
  const __m256i hi = _mm256_cvtepi32_epi64(_mm256_extracti128_si256(v, 1));
  const __m256i s = _mm256_add_epi64(lo, hi);
  const __m128i t = _mm_add_epi64(_mm256_castsi256_si128(s), _mm256_extracti128_si256(s, 1));
  return _mm_cvtsi128_si64(t) + _mm_extract_epi64(t, 1);
}

[[gnu::target("avx2")]] std::int64_t fixed_ssd_avx2(const std::int16_t* a, const std::int16_t* b, int n) {
  std::int64_t sum = 0;
  for (int start = 0; start < n; start += kBlock) {
    const int end = std::min(n, start + kBlock);
    __m256i acc = _mm256_setzero_si256();
    int i = start;
    for (; i + 16 <= end; i += 16) {
      const __m256i d = _mm256_sub_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + i)),
                                         _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + i)));
      acc = _mm256_add_epi32(acc, _mm256_madd_epi16(d, d));
    }
    if (i + 8 <= end) {
      const __m128i d = _mm_sub_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + i)),
                                      _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i)));
      acc = _mm256_add_epi32(acc, _mm256_zextsi128_si256(_mm_madd_epi16(d, d)));
      i += 8;
    }
    sum += hsum_epi32(acc) + fixed_ssd_scalar(a + i, b + i, end - i);
  }
  return sum;
}

// Bytes: widened to int16 (8 bits square into a madd pair without any risk).
[[gnu::target("avx2")]] std::int64_t fixed_ssd_avx2(const std::uint8_t* a, const std::uint8_t* b, int n) {
  std::int64_t sum = 0;
  for (int start = 0; start < n; start += kBlock) {
    const int end = std::min(n, start + kBlock);
    __m256i acc = _mm256_setzero_si256();
    int i = start;
    for (; i + 16 <= end; i += 16) {
      const __m256i d = _mm256_sub_epi16(_mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + i))),
                                         _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i))));
      acc = _mm256_add_epi32(acc, _mm256_madd_epi16(d, d));
    }
    if (i + 8 <= end) {
      const __m128i d = _mm_sub_epi16(_mm_cvtepu8_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(a + i))),
                                      _mm_cvtepu8_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(b + i))));
      acc = _mm256_add_epi32(acc, _mm256_zextsi128_si256(_mm_madd_epi16(d, d)));
      i += 8;
    }
    sum += hsum_epi32(acc) + fixed_ssd_scalar(a + i, b + i, end - i);
  }
  return sum;
}

[[gnu::target("avx512f,avx512bw,avx512vl")]] std::int64_t fixed_ssd_avx512(const std::uint8_t* a, const std::uint8_t* b,
                                                                           int n) {
  std::int64_t sum = 0;
  for (int start = 0; start < n; start += kBlock) {
    const int end = std::min(n, start + kBlock);
    __m512i acc = _mm512_setzero_si512();
    for (int i = start; i < end; i += 32) {
      const __mmask32 m = end - i >= 32 ? ~__mmask32(0) : (__mmask32(1) << (end - i)) - 1;
      const __m512i d = _mm512_sub_epi16(_mm512_cvtepu8_epi16(_mm256_maskz_loadu_epi8(m, a + i)),
                                         _mm512_cvtepu8_epi16(_mm256_maskz_loadu_epi8(m, b + i)));
      acc = _mm512_add_epi32(acc, _mm512_madd_epi16(d, d));
    }
    const __m512i wide = _mm512_add_epi64(_mm512_cvtepi32_epi64(_mm512_castsi512_si256(acc)),
                                          _mm512_cvtepi32_epi64(_mm512_extracti64x4_epi64(acc, 1)));
    sum += _mm512_reduce_add_epi64(wide);
  }
  return sum;
}

[[gnu::target("avx512f,avx512bw")]] std::int64_t fixed_ssd_avx512(const std::int16_t* a, const std::int16_t* b,
                                                                  int n) {
  std::int64_t sum = 0;
  for (int start = 0; start < n; start += kBlock) {
    const int end = std::min(n, start + kBlock);
    __m512i acc = _mm512_setzero_si512();
    for (int i = start; i < end; i += 32) {
      const __mmask32 m = end - i >= 32 ? ~__mmask32(0) : (__mmask32(1) << (end - i)) - 1;
      const __m512i d = _mm512_sub_epi16(_mm512_maskz_loadu_epi16(m, a + i), _mm512_maskz_loadu_epi16(m, b + i));
      acc = _mm512_add_epi32(acc, _mm512_madd_epi16(d, d));
    }
    const __m512i wide = _mm512_add_epi64(_mm512_cvtepi32_epi64(_mm512_castsi512_si256(acc)),
                                          _mm512_cvtepi32_epi64(_mm512_extracti64x4_epi64(acc, 1)));
    sum += _mm512_reduce_add_epi64(wide);
  }
  return sum;
}

template <class T>
using FixedSsd = std::int64_t (*)(const T*, const T*, int);

// Whole patches: `rows` rows of n values, `pitch` values apart in each image,
// summed row by row until the sum reaches `limit` (the early exit). One call
// a candidate, not one a row: a candidate costs a few rows, and the call and
// the 64-bit reduction per row were as dear as the arithmetic. A row of up to
// kShortRow values (a 5x5 patch row of StyLit's 9 channels, style and 6
// guide components, is 45) is reduced in 32 bits: its
// sum, and so every partial sum of its lanes, is at most
// 128 * 4095^2 < 2^31. Longer rows go through the blocked row kernels.
constexpr int kShortRow = 128;

template <class T>
using PatchSsd = std::int64_t (*)(const T*, std::size_t, const T*, std::size_t, int, int, std::int64_t);

// Horizontal sum of 8 int32 lanes (exact: see kShortRow).
[[gnu::target("avx2")]] inline std::int32_t hsum32(__m256i v) {
  const __m128i s = _mm_add_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
  const __m128i t = _mm_add_epi32(s, _mm_unpackhi_epi64(s, s));
  return _mm_cvtsi128_si32(_mm_add_epi32(t, _mm_shuffle_epi32(t, 1)));
}

template <class T, FixedSsd<T> Row>
std::int64_t patch_rows(const T* a, std::size_t pa, const T* b, std::size_t pb, int rows, int n, std::int64_t limit) {
  std::int64_t sum = 0;
  for (int k = 0; k < rows && sum < limit; ++k) sum += Row(a + k * pa, b + k * pb, n);
  return sum;
}

[[gnu::target("avx512f,avx512bw,avx512vl")]] inline __m512i load_row16(const std::int16_t* p, __mmask32 m) {
  return _mm512_maskz_loadu_epi16(m, p);
}
[[gnu::target("avx512f,avx512bw,avx512vl")]] inline __m512i load_row16(const std::uint8_t* p, __mmask32 m) {
  return _mm512_cvtepu8_epi16(_mm256_maskz_loadu_epi8(m, p));
}

template <class T>
[[gnu::target("avx512f,avx512bw,avx512vl")]] std::int64_t patch_ssd_avx512(const T* a, std::size_t pa, const T* b,
                                                                  std::size_t pb, int rows, int n,
                                                                  std::int64_t limit) {
  if (n > kShortRow) return patch_rows<T, fixed_ssd_avx512>(a, pa, b, pb, rows, n, limit);
  std::int64_t sum = 0;
  for (int k = 0; k < rows && sum < limit; ++k, a += pa, b += pb) {
    __m512i acc = _mm512_setzero_si512();
    for (int i = 0; i < n; i += 32) {
      const __mmask32 m = n - i >= 32 ? ~__mmask32(0) : (__mmask32(1) << (n - i)) - 1;
      const __m512i d = _mm512_sub_epi16(load_row16(a + i, m), load_row16(b + i, m));
      acc = _mm512_add_epi32(acc, _mm512_madd_epi16(d, d));
    }
    sum += hsum32(_mm256_add_epi32(_mm512_castsi512_si256(acc), _mm512_extracti64x4_epi64(acc, 1)));
  }
  return sum;
}

[[gnu::target("avx2")]] inline __m256i load16(const std::int16_t* p) {
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}
[[gnu::target("avx2")]] inline __m256i load16(const std::uint8_t* p) {
  return _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
}

[[gnu::target("avx2")]] inline __m128i load8(const std::int16_t* p) {
  return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
}
[[gnu::target("avx2")]] inline __m128i load8(const std::uint8_t* p) {
  return _mm_cvtepu8_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
}

// Lanes [8 - r, 8) set, r in 1..7: the last r values of an 8-value load.
[[gnu::target("avx2")]] inline __m128i last_lanes(int r) {
  static const std::int16_t kLanes[16] = {0, 0, 0, 0, 0, 0, 0, 0, -1, -1, -1, -1, -1, -1, -1, -1};
  return _mm_loadu_si128(reinterpret_cast<const __m128i*>(kLanes + r));
}

template <class T>
[[gnu::target("avx2")]] std::int64_t patch_ssd_avx2(const T* a, std::size_t pa, const T* b, std::size_t pb,
                                                    int rows, int n, std::int64_t limit) {
  if (n > kShortRow) return patch_rows<T, fixed_ssd_avx2>(a, pa, b, pb, rows, n, limit);
  if (n < 8) return patch_rows<T, fixed_ssd_scalar<T>>(a, pa, b, pb, rows, n, limit);
  // Pixels are not padded, so a row need not be a multiple of 8 values: its
  // last r values are loaded with the 8 that end the row (nothing past the
  // row is read) and the lanes summed already are masked off.
  const int tail = n % 8, body = n - tail;
  const __m128i keep = tail ? last_lanes(tail) : _mm_setzero_si128();
  std::int64_t sum = 0;
  for (int k = 0; k < rows && sum < limit; ++k, a += pa, b += pb) {
    __m256i acc = _mm256_setzero_si256();
    int i = 0;
    for (; i + 16 <= body; i += 16) {
      const __m256i d = _mm256_sub_epi16(load16(a + i), load16(b + i));
      acc = _mm256_add_epi32(acc, _mm256_madd_epi16(d, d));
    }
    if (i < body) {
      const __m128i d = _mm_sub_epi16(load8(a + i), load8(b + i));
      acc = _mm256_add_epi32(acc, _mm256_zextsi128_si256(_mm_madd_epi16(d, d)));
    }
    if (tail) {
      const __m128i d = _mm_and_si128(_mm_sub_epi16(load8(a + n - 8), load8(b + n - 8)), keep);
      acc = _mm256_add_epi32(acc, _mm256_zextsi128_si256(_mm_madd_epi16(d, d)));
    }
    sum += hsum32(acc);
  }
  return sum;
}

template <class T>
FixedSsd<T> kernel_of(FixedKernel k) {
  switch (k) {
    case FixedKernel::Scalar: return fixed_ssd_scalar<T>;
    case FixedKernel::Avx2: return fixed_ssd_avx2;
    case FixedKernel::Avx512: return fixed_ssd_avx512;
    case FixedKernel::Best: break;
  }
  if (fixed_kernel_supported(FixedKernel::Avx512)) return fixed_ssd_avx512;
  if (fixed_kernel_supported(FixedKernel::Avx2)) return fixed_ssd_avx2;
  return fixed_ssd_scalar<T>;
}

template <class T>
PatchSsd<T> patch_kernel_of(FixedKernel k) {
  switch (k) {
    case FixedKernel::Scalar: return patch_rows<T, fixed_ssd_scalar<T>>;
    case FixedKernel::Avx2: return patch_ssd_avx2<T>;
    case FixedKernel::Avx512: return patch_ssd_avx512<T>;
    case FixedKernel::Best: break;
  }
  if (fixed_kernel_supported(FixedKernel::Avx512)) return patch_ssd_avx512<T>;
  if (fixed_kernel_supported(FixedKernel::Avx2)) return patch_ssd_avx2<T>;
  return patch_rows<T, fixed_ssd_scalar<T>>;
}

// Picked once, at load time.
const PatchSsd<std::int16_t> best_patch_ssd16 = patch_kernel_of<std::int16_t>(FixedKernel::Best);
const PatchSsd<std::uint8_t> best_patch_ssd8 = patch_kernel_of<std::uint8_t>(FixedKernel::Best);

std::int64_t best_patch_ssd(const std::int16_t* a, std::size_t pa, const std::int16_t* b, std::size_t pb, int rows,
                            int n, std::int64_t limit) {
  return best_patch_ssd16(a, pa, b, pb, rows, n, limit);
}
std::int64_t best_patch_ssd(const std::uint8_t* a, std::size_t pa, const std::uint8_t* b, std::size_t pb, int rows,
                            int n, std::int64_t limit) {
  return best_patch_ssd8(a, pa, b, pb, rows, n, limit);
}

}  // namespace

bool fixed_kernel_supported(FixedKernel kernel) {
  __builtin_cpu_init();
  switch (kernel) {
    case FixedKernel::Avx2: return __builtin_cpu_supports("avx2");
    case FixedKernel::Avx512:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
             __builtin_cpu_supports("avx512vl");
    default: return true;
  }
}

std::int64_t fixed_ssd(const std::int16_t* a, const std::int16_t* b, int n, FixedKernel kernel) {
  if (!fixed_kernel_supported(kernel)) throw ValueError("fixed-point kernel not supported by this CPU");
  return kernel_of<std::int16_t>(kernel)(a, b, n);
}

std::int64_t fixed_ssd(const std::uint8_t* a, const std::uint8_t* b, int n, FixedKernel kernel) {
  if (!fixed_kernel_supported(kernel)) throw ValueError("fixed-point kernel not supported by this CPU");
  return kernel_of<std::uint8_t>(kernel)(a, b, n);
}

std::int64_t fixed_patch_ssd(const std::int16_t* a, std::size_t pitch_a, const std::int16_t* b, std::size_t pitch_b,
                             int rows, int n, std::int64_t limit, FixedKernel kernel) {
  if (!fixed_kernel_supported(kernel)) throw ValueError("fixed-point kernel not supported by this CPU");
  return patch_kernel_of<std::int16_t>(kernel)(a, pitch_a, b, pitch_b, rows, n, limit);
}

std::int64_t fixed_patch_ssd(const std::uint8_t* a, std::size_t pitch_a, const std::uint8_t* b, std::size_t pitch_b,
                             int rows, int n, std::int64_t limit, FixedKernel kernel) {
  if (!fixed_kernel_supported(kernel)) throw ValueError("fixed-point kernel not supported by this CPU");
  return patch_kernel_of<std::uint8_t>(kernel)(a, pitch_a, b, pitch_b, rows, n, limit);
}

std::vector<float> expand_window(const float* window, int radius, int stride) {
  const int side = 2 * radius + 1;
  std::vector<float> out;
  out.reserve(std::size_t(side) * side * stride);
  for (int i = 0; i < side * side; ++i) out.insert(out.end(), std::size_t(stride), window[i]);
  return out;
}

void sample_bilinear(const float* data, int width, int height, int stride, int channels, float x,
                     float y, float* out) {
  x = std::clamp(x, 0.0f, float(width - 1));
  y = std::clamp(y, 0.0f, float(height - 1));
  const int x0 = std::min(int(x), width - 2 < 0 ? 0 : width - 2);
  const int y0 = std::min(int(y), height - 2 < 0 ? 0 : height - 2);
  const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  const float fx = x - x0, fy = y - y0;
  const float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
  const float* p00 = data + (std::size_t(y0) * width + x0) * stride;
  const float* p10 = data + (std::size_t(y0) * width + x1) * stride;
  const float* p01 = data + (std::size_t(y1) * width + x0) * stride;
  const float* p11 = data + (std::size_t(y1) * width + x1) * stride;
  for (int c = 0; c < channels; ++c) out[c] = w00 * p00[c] + w10 * p10[c] + w01 * p01[c] + w11 * p11[c];
}

namespace {

// Sum of squared differences over n floats; the simd pragma lets the compiler
// keep vector partial sums (no -ffast-math needed).
[[gnu::always_inline]] inline float ssd(const float* a, const float* b, int n) {
  float sum = 0.0f;
#pragma omp simd reduction(+ : sum)
  for (int i = 0; i < n; ++i) {
    const float d = a[i] - b[i];
    sum += d * d;
  }
  return sum;
}

[[gnu::always_inline]] inline float weighted_ssd(const float* a, const float* b, const float* w, int n) {
  float sum = 0.0f;
#pragma omp simd reduction(+ : sum)
  for (int i = 0; i < n; ++i) {
    const float d = a[i] - b[i];
    sum += w[i] * d * d;
  }
  return sum;
}

struct Window {
  int dx0, dx1, dy0, dy1;  // inclusive offsets of the target patch inside the target
};

[[gnu::always_inline]] inline Window clip(const PatchSpace& s, int tx, int ty) {
  const int r = s.radius;
  return Window{std::max(-r, -tx), std::min(r, s.target->width - 1 - tx), std::max(-r, -ty),
                std::min(r, s.target->height - 1 - ty)};
}

// Helpers are always inlined so that they are compiled into each clone of
// patch_distance (AVX2 and baseline).

// Axis-aligned patches: each patch row is one contiguous run in both images.
template <bool Weighted>
[[gnu::always_inline]] inline float distance_aligned(const PatchSpace& s, int sx, int sy, int tx, int ty, float cutoff) {
  const Window w = clip(s, tx, ty);
  const int n = (w.dx1 - w.dx0 + 1) * s.source->stride;
  float sum = 0.0f;
  for (int dy = w.dy0; dy <= w.dy1; ++dy) {
    const float* a = s.source->pixel(sx + w.dx0, sy + dy);
    const float* b = s.target->pixel(tx + w.dx0, ty + dy);
    if constexpr (Weighted)
      sum += weighted_ssd(a, b, s.target_weights->pixel(tx + w.dx0, ty + dy), n);
    else
      sum += ssd(a, b, n);
    if (sum >= cutoff) return sum;
  }
  return sum;
}

// Axis-aligned patches over quantized features: exact integer row sums,
// scaled by step^2 into the float energy.
template <class T>
float distance_fixed(const PatchSpace& s, int sx, int sy, int tx, int ty, float cutoff) {
  const Window w = clip(s, tx, ty);
  const int n = (w.dx1 - w.dx0 + 1) * s.source->stride;
  const double step2 = double(s.source->step) * s.source->step;
  const double limit = double(cutoff) / step2;
  auto row = [](const FeatureImage& f, int x, int y) {
    if constexpr (std::is_same_v<T, std::uint8_t>)
      return f.fixed8_pixel(x, y);
    else
      return f.fixed_pixel(x, y);
  };
  // The integer sum reaches `limit` exactly when it reaches its ceiling.
  constexpr std::int64_t kNoStop = std::numeric_limits<std::int64_t>::max();
  const bool weighted = s.weighted_patches && s.weighted_patches[std::size_t(ty) * s.target->width + tx];
  const std::int64_t stop = weighted || !(limit < 9e18) ? kNoStop : std::int64_t(std::ceil(limit));
  const std::size_t pitch_a = std::size_t(s.source->width) * s.source->stride;
  const std::size_t pitch_b = std::size_t(s.target->width) * s.target->stride;
  const std::int64_t sum = best_patch_ssd(row(*s.source, sx + w.dx0, sy + w.dy0), pitch_a,
                                          row(*s.target, tx + w.dx0, ty + w.dy0), pitch_b, w.dy1 - w.dy0 + 1, n,
                                          stop);
  if (!weighted) return float(double(sum) * step2);
  // Weighted target pixels: their channels count (weight - 1) times more, on
  // the same integer differences, so the result is the weighted SSD of the
  // quantized features (no early stop: the correction may lower the sum).
  double corrected = double(sum);
  for (int dy = w.dy0; dy <= w.dy1; ++dy)
    for (int dx = w.dx0; dx <= w.dx1; ++dx) {
      if (!s.weighted_pixels[std::size_t(ty + dy) * s.target->width + tx + dx]) continue;
      const T* a = row(*s.source, sx + dx, sy + dy);
      const T* b = row(*s.target, tx + dx, ty + dy);
      const float* weight = s.target_weights->pixel(tx + dx, ty + dy);
      for (int c = 0; c < s.target->stride; ++c) {
        const double d = double(a[c]) - double(b[c]);
        corrected += (double(weight[c]) - 1.0) * d * d;
      }
    }
  return float(std::max(0.0, corrected) * step2);
}

[[gnu::always_inline]] inline float doubly_weighted_ssd(const float* a, const float* b, const float* w,
                                                        const float* v, int n) {
  float sum = 0.0f;
#pragma omp simd reduction(+ : sum)
  for (int i = 0; i < n; ++i) {
    const float d = a[i] - b[i];
    sum += w[i] * v[i] * d * d;
  }
  return sum;
}

// Axis-aligned patches under a window: each patch row is one run weighted by
// the window expanded to every channel (one pixel's channels at a time were
// short sums, each reduced on its own: the coherent method's hot loop).
[[gnu::always_inline]] inline float distance_windowed(const PatchSpace& s, int sx, int sy, int tx, int ty,
                                                      float cutoff) {
  const Window w = clip(s, tx, ty);
  const int stride = s.source->stride, side = 2 * s.radius + 1, n = (w.dx1 - w.dx0 + 1) * stride;
  float sum = 0.0f;
  for (int dy = w.dy0; dy <= w.dy1; ++dy) {
    const float* k = s.window_channels + std::size_t(((dy + s.radius) * side + w.dx0 + s.radius) * stride);
    const float* a = s.source->pixel(sx + w.dx0, sy + dy);
    const float* b = s.target->pixel(tx + w.dx0, ty + dy);
    sum += s.target_weights ? doubly_weighted_ssd(a, b, k, s.target_weights->pixel(tx + w.dx0, ty + dy), n)
                            : weighted_ssd(a, b, k, n);
    if (sum >= cutoff) return sum;
  }
  return sum;
}

// Rotated patches: the source is sampled bilinearly along rotated offsets.
[[gnu::always_inline]] inline float distance_rotated(const PatchSpace& s, int sx, int sy, int tx, int ty, float cutoff) {
  const Window w = clip(s, tx, ty);
  const int stride = s.source->stride;
  const float phi = s.rotation(sx, sy, tx, ty);
  const float c = std::cos(phi), sn = std::sin(phi);
  const int side = 2 * s.radius + 1;
  float sample[256];
  float sum = 0.0f;
  for (int dy = w.dy0; dy <= w.dy1; ++dy) {
    for (int dx = w.dx0; dx <= w.dx1; ++dx) {
      const float weight = s.window ? s.window[(dy + s.radius) * side + dx + s.radius] : 1.0f;
      const float x = sx + c * dx - sn * dy, y = sy + sn * dx + c * dy;
      sample_bilinear(s.source->data.data(), s.source->width, s.source->height, stride, stride, x, y,
                      sample);
      const float* b = s.target->pixel(tx + dx, ty + dy);
      sum += weight * (s.target_weights ? weighted_ssd(sample, b, s.target_weights->pixel(tx + dx, ty + dy), stride)
                                        : ssd(sample, b, stride));
    }
    if (sum >= cutoff) return sum;
  }
  return sum;
}

}  // namespace

// The hot spot of every solver: compiled for AVX2 and a baseline, picked at
// load time, so one binary is fast on new CPUs and still runs on old ones.
__attribute__((target_clones("avx2", "default")))
float patch_distance(const PatchSpace& space, int sx, int sy, int tx, int ty, float cutoff) {
  if (space.source->quantized())
    return space.source->bytes() ? distance_fixed<std::uint8_t>(space, sx, sy, tx, ty, cutoff)
                                 : distance_fixed<std::int16_t>(space, sx, sy, tx, ty, cutoff);
  if (space.rotated() || (space.window && !space.window_channels))
    return distance_rotated(space, sx, sy, tx, ty, cutoff);
  if (space.window) return distance_windowed(space, sx, sy, tx, ty, cutoff);
  if (space.target_weights) return distance_aligned<true>(space, sx, sy, tx, ty, cutoff);
  return distance_aligned<false>(space, sx, sy, tx, ty, cutoff);
}

}  // namespace tempera

#pragma once
// The weighted mode of a pixel's vote (OutputMode::Mode, Color Me Noisy
// §3.2): of the colours that the patches covering the pixel bring along, the
// one with the most similar others,
//   score(j) = sum over k != j of exp(-|v_j - v_k|^2 / h^2)
// (exp: the engine's own, within about 2 float steps, the same on every CPU),
// the first best in the order the candidates came.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "tempera/engine/patch_distance.hpp"  // FixedKernel: which SIMD variant

namespace tempera {

// One pixel's candidates, stored channel by channel (a plane per channel), so
// that the AVX2 kernel compares eight candidates at a time.
class ModeCandidates {
 public:
  // Room for `capacity` candidates of `channels` channels; empties the list.
  void reset(int channels, std::size_t capacity);
  void clear() { n_ = 0; }
  void push(const float* value) {
    for (int ch = 0; ch < channels_; ++ch) planes_[std::size_t(ch) * stride_ + n_] = value[ch];
    ++n_;
  }
  void push(const ModeCandidates& from, std::size_t j) {
    for (int ch = 0; ch < channels_; ++ch) planes_[std::size_t(ch) * stride_ + n_] = from.plane(ch)[j];
    ++n_;
  }
  std::size_t size() const { return n_; }
  int channels() const { return channels_; }
  const float* plane(int ch) const { return planes_.data() + std::size_t(ch) * stride_; }
  void copy(std::size_t j, float* out) const {
    for (int ch = 0; ch < channels_; ++ch) out[ch] = plane(ch)[j];
  }

 private:
  int channels_ = 0;
  std::size_t stride_ = 0, n_ = 0;
  std::vector<float> planes_;
};

// A thread's working memory for weighted_mode (kept between pixels).
struct ModeScratch {
  ModeCandidates unique;
  std::vector<float> count, score;
  std::vector<std::uint32_t> first;
  std::vector<float> kernel;  // the AVX2 variant's pair kernels, a row of 8-aligned columns per colour
};

// The kernel of two colours whose squared distance over h^2 is x: exp(-x),
// or 0 where that is below half a float step of 1 (x > 17.5).
float mode_kernel(float x);

// Index (into `candidates`) of the weighted mode with kernel width `bandwidth`.
// Every variant gives the same index: the same floats are summed in the same
// order (FixedKernel::Scalar is the reference; Best picks AVX2 where the CPU
// has it).
std::size_t weighted_mode(const ModeCandidates& candidates, float bandwidth, ModeScratch& scratch,
                          FixedKernel kernel = FixedKernel::Best);

}  // namespace tempera

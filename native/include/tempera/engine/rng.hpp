#pragma once
// Counter-based random numbers: a value is a pure function of (seed, stream,
// counter), so parallel code draws the same numbers whatever the schedule.
#include <cstdint>

namespace tempera {

inline std::uint64_t mix64(std::uint64_t z) {  // splitmix64 finalizer
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t stream) : state_(mix64(seed ^ mix64(stream + 0x632BE59BD9B4E019ull))) {}
  std::uint64_t next() { return mix64(state_ += 0x9E3779B97F4A7C15ull); }
  // Uniform integer in [0, n).
  int below(int n) { return int((next() >> 33) % std::uint64_t(n)); }
  // Uniform integer in [lo, hi].
  int between(int lo, int hi) { return lo + below(hi - lo + 1); }
  float uniform() { return float(next() >> 40) * (1.0f / 16777216.0f); }

 private:
  std::uint64_t state_;
};

}  // namespace tempera

#pragma once
// LSD radix sort of floats by their bits: the same ascending order as
// std::sort for any values but NaN, in three linear passes instead of
// n log n comparisons. The error budget sorts a million candidate errors
// every round for its knee fit (error_budget.cpp).
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

namespace tempera {

// Maps a float's bits to an unsigned key that orders like the value: negative
// floats have every bit flipped (larger magnitude sorts first), non-negative
// ones only the sign bit. -0 sorts before +0, which compare equal anyway.
inline std::uint32_t float_order_key(float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits & 0x80000000u ? ~bits : bits | 0x80000000u;
}

inline float float_from_order_key(std::uint32_t key) {
  const std::uint32_t bits = key & 0x80000000u ? key & 0x7FFFFFFFu : ~key;
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// Sorts `values` ascending. The keys pass back and forth between `scratch`
// and `values` itself (its floats then hold key bits, copied with memcpy and
// never read as numbers), so the sort needs n keys of scratch, not 2n: the
// error budget's sort was part of the peak memory. `scratch` is reused
// between calls to spare the allocation.
inline void radix_sort(std::vector<float>& values, std::vector<std::uint32_t>& scratch) {
  constexpr int kBits = 11, kPasses = 3;  // 3 x 11 bits cover the 32-bit key
  constexpr std::uint32_t kBuckets = 1u << kBits;
  const std::size_t n = values.size();
  scratch.resize(n);
  float* v = values.data();
  std::uint32_t* keys = scratch.data();
  const auto key_in_values = [v](std::size_t i) {
    std::uint32_t key;
    std::memcpy(&key, v + i, sizeof key);
    return key;
  };
  std::array<std::array<std::size_t, kBuckets>, kPasses> count{};
  for (std::size_t i = 0; i < n; ++i) {
    keys[i] = float_order_key(v[i]);
    for (int pass = 0; pass < kPasses; ++pass) ++count[pass][(keys[i] >> (pass * kBits)) & (kBuckets - 1)];
  }
  for (int pass = 0; pass < kPasses; ++pass) {
    std::size_t start = 0;
    for (auto& c : count[pass]) {
      const std::size_t size = c;
      c = start;
      start += size;
    }
    const auto bucket = [&](std::uint32_t key) { return count[pass][(key >> (pass * kBits)) & (kBuckets - 1)]++; };
    if (pass % 2 == 0)  // scratch -> values
      for (std::size_t i = 0; i < n; ++i) std::memcpy(v + bucket(keys[i]), &keys[i], sizeof keys[i]);
    else  // values -> scratch
      for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t key = key_in_values(i);
        keys[bucket(key)] = key;
      }
  }
  static_assert(kPasses % 2 == 1, "the sorted keys end in `values`");
  for (std::size_t i = 0; i < n; ++i) v[i] = float_from_order_key(key_in_values(i));
}

}  // namespace tempera

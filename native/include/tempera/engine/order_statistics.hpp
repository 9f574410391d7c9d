#pragma once
// Exact order statistics of a set of floats that is never gathered. The error
// budget reads about a thousand ranks of a million candidate errors each
// round for its knee fit (error_budget.cpp); a copy of the errors and a sort's
// scratch were 8 bytes a source at the peak of the still's memory. A radix
// select instead: passes over the values, each counting one byte of their
// order keys under the prefixes the wanted ranks have taken so far.
#include <cstdint>
#include <cstring>
#include <vector>

#include "tempera/engine/error.hpp"
#include "tempera/engine/parallel.hpp"

namespace tempera {

// Maps a float's bits to an unsigned key that orders like the value: negative
// floats have every bit flipped (larger magnitude sorts first), non-negative
// ones only the sign bit. -0 orders before +0, which compare equal anyway.
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

// The values of a set at ranks of its ascending order, as std::sort orders
// them (any floats but NaN). The set is `for_each_value(begin, end, f)`, which
// calls f(float) for each value held by the indices [begin, end) of
// [0, index_count), the same values at every call; parts are read in parallel.
// Construction counts the set (one pass); each values_at() takes three more.
// Transient memory: a count per byte value under each distinct prefix of the
// wanted ranks (at most 256 x ranks a pass), per part.
template <class ForEachValue>
class RadixSelect {
 public:
  RadixSelect(const ForEachValue& for_each_value, std::size_t index_count, int threads)
      : for_each_value_(for_each_value), index_count_(index_count), threads_(resolve_threads(threads)) {
    top_count_ = count_bytes(0, {}, 1);
    for (std::uint32_t c : top_count_) size_ += c;
  }

  // How many values the set has.
  std::size_t size() const { return size_; }

  // The values at `ranks` (each below size()), in the order of `ranks`.
  std::vector<float> values_at(const std::vector<std::size_t>& ranks) const {
    const std::size_t wanted = ranks.size();
    for (std::size_t r : ranks)
      if (r >= size_) throw ValueError("internal: order statistic rank past the set's size");
    // Per wanted rank: the node of its key's prefix so far (the distinct
    // prefixes of the wanted ranks, numbered per depth), its rank among that
    // node's values, and the key's bits found.
    std::vector<std::uint32_t> node(wanted, 0), key(wanted, 0);
    std::vector<std::size_t> rank_in_node(ranks);
    std::vector<std::vector<std::uint32_t>> child;  // per depth: node * 256 + byte -> node below, or kNone
    std::uint32_t nodes = 1;
    for (int depth = 0; depth < 4; ++depth) {
      const std::vector<std::uint32_t> count = depth == 0 ? top_count_ : count_bytes(depth, child, nodes);
      const bool last = depth == 3;  // the key is whole: no nodes below to number
      std::vector<std::uint32_t> next(last ? 0 : std::size_t(nodes) * kRadix, kNone);
      std::uint32_t next_nodes = 0;
      for (std::size_t i = 0; i < wanted; ++i) {
        const std::uint32_t* c = &count[std::size_t(node[i]) * kRadix];
        std::uint32_t b = 0;
        while (rank_in_node[i] >= c[b]) rank_in_node[i] -= c[b++];  // stops below 256 for a rank in the set
        key[i] |= b << shift(depth);
        if (last) continue;
        std::uint32_t& id = next[std::size_t(node[i]) * kRadix + b];
        if (id == kNone) id = next_nodes++;
        node[i] = id;
      }
      child.push_back(std::move(next));
      nodes = next_nodes;
    }
    std::vector<float> out(wanted);
    for (std::size_t i = 0; i < wanted; ++i) out[i] = float_from_order_key(key[i]);
    return out;
  }

 private:
  static constexpr std::uint32_t kRadix = 256, kNone = ~0u;
  static int shift(int depth) { return 24 - 8 * depth; }

  // Counts, under each node at `depth`, the values by their key's byte there.
  // Each part counts on its own; the sums do not depend on the thread timing.
  std::vector<std::uint32_t> count_bytes(int depth, const std::vector<std::vector<std::uint32_t>>& child,
                                         std::uint32_t nodes) const {
    const int parts = threads_;
    const std::size_t cells = std::size_t(nodes) * kRadix;
    std::vector<std::vector<std::uint32_t>> counts(std::size_t(parts), std::vector<std::uint32_t>(cells, 0));
    parallel_for(parts, parts, [&](int part) {
      std::uint32_t* count = counts[std::size_t(part)].data();
      const std::size_t begin = index_count_ * std::size_t(part) / std::size_t(parts);
      const std::size_t end = index_count_ * std::size_t(part + 1) / std::size_t(parts);
      for_each_value_(begin, end, [&](float v) {
        const std::uint32_t k = float_order_key(v);
        std::uint32_t n = 0;
        for (int d = 0; d < depth && n != kNone; ++d) n = child[std::size_t(d)][n * kRadix + ((k >> shift(d)) & 255)];
        if (n != kNone) ++count[n * kRadix + ((k >> shift(depth)) & 255)];
      });
    });
    for (int part = 1; part < parts; ++part)
      for (std::size_t c = 0; c < cells; ++c) counts[0][c] += counts[std::size_t(part)][c];
    return std::move(counts[0]);
  }

  const ForEachValue& for_each_value_;
  std::size_t index_count_;
  int threads_;
  std::vector<std::uint32_t> top_count_;
  std::size_t size_ = 0;
};

}  // namespace tempera

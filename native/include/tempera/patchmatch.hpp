#pragma once
// Nearest-neighbour fields and PatchMatch (Barnes et al. 2009): propagation and
// random search, parallel over fixed bands of rows. Pixels outside a band are
// read from a snapshot taken at the start of each iteration, so the result
// depends on the seed only, never on the thread count or schedule.
#include <cstdint>
#include <vector>

#include "tempera/patch_distance.hpp"

namespace tempera {

// For each target pixel: the center of its source patch and their distance.
struct Nnf {
  int width = 0;
  int height = 0;
  std::vector<std::int32_t> x, y;
  std::vector<float> dist;

  Nnf() = default;
  Nnf(int w, int h) : width(w), height(h), x(std::size_t(w) * h), y(std::size_t(w) * h), dist(std::size_t(w) * h) {}
  std::size_t index(int tx, int ty) const { return std::size_t(ty) * width + tx; }
};

// Which matches are allowed.
struct SearchConstraints {
  std::vector<std::uint8_t> source_valid;   // per source pixel: may be a patch center
  std::vector<std::uint8_t> target_active;  // per target pixel: is synthesized
  // Optional segment labels: a target pixel only matches sources with its label.
  std::vector<std::int32_t> source_segment, target_segment;
  // Optional extra cost per source center (occurrence penalty).
  std::vector<float> source_penalty;
  // Valid source centers (indices), per segment label; filled by finalize().
  std::vector<std::vector<std::int32_t>> valid_by_segment;

  // Builds valid_by_segment; throws ValueError if a target segment has no source.
  void finalize();
  int segment_of_target(std::size_t i) const { return target_segment.empty() ? 0 : target_segment[i]; }
  int segment_of_source(std::size_t i) const { return source_segment.empty() ? 0 : source_segment[i]; }
  bool allowed(std::size_t source_index, int segment) const {
    return source_valid[source_index] && segment_of_source(source_index) == segment;
  }
  float penalty(std::size_t source_index) const {
    return source_penalty.empty() ? 0.0f : source_penalty[source_index];
  }
};

struct PatchMatchParams {
  int iterations = 4;
  std::uint64_t seed = 1;
  int threads = 0;
  int band_rows = 32;
  int random_tries_per_scale = 1;
};

// Random valid source for every active target pixel, with distances.
void random_nnf(const PatchSpace& space, const SearchConstraints& constraints, Nnf& nnf,
                std::uint64_t seed, int threads);

// Recomputes nnf.dist for the current features (e.g. after voting changed B').
void refresh_distances(const PatchSpace& space, const SearchConstraints& constraints, Nnf& nnf,
                       int threads);

// Improves `nnf` in place; only ever accepts better matches.
void patchmatch(const PatchSpace& space, const SearchConstraints& constraints, Nnf& nnf,
                const PatchMatchParams& params, std::uint64_t stream);

// NNF of a level twice as large (rotation-aware): children inherit the parent
// match shifted by their offset within the parent pixel.
Nnf upsample_nnf(const Nnf& coarse, const PatchSpace& fine_space, const SearchConstraints& fine_constraints,
                 int fine_width, int fine_height);

// Source position proposed for target q by a neighbour q + d whose match is
// (nx, ny): the neighbour's source shifted back by d, rotated into source space.
inline void propagate_candidate(const PatchSpace& space, int nx, int ny, int ntx, int nty, int dx, int dy,
                                int& cx, int& cy) {
  if (!space.rotated()) {
    cx = nx - dx;
    cy = ny - dy;
    return;
  }
  float ox, oy;
  rotate_offset(space.rotation(nx, ny, ntx, nty), float(dx), float(dy), ox, oy);
  cx = int(std::lround(nx - ox));
  cy = int(std::lround(ny - oy));
}

}  // namespace tempera

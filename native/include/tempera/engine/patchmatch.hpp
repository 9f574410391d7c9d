#pragma once
// PatchMatch (Barnes et al. 2009) over offset fields: propagation, random
// search, candidates injected by the method (Bénard's ribbons) and, for video
// exemplars, the same match one frame earlier and later. Parallel over fixed
// bands of rows; pixels outside a band are read from a snapshot taken at the
// start of each iteration, so the result depends on the seed only, never on
// the thread count or schedule.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "tempera/engine/energy_term.hpp"
#include "tempera/engine/offset_field.hpp"
#include "tempera/engine/patch_distance.hpp"

namespace tempera {

// Source indices in ascending order, stored as runs of consecutive indices:
// the valid sources of a segment are whole rows of an exemplar but its
// margins (or a mask's spans), a few thousand runs where a list of every
// index took 4 bytes a source pixel (4 MB at 1 Mpix, all through the solve).
class SourceIndexRuns {
 public:
  void push_back(std::int32_t index) {  // ascending
    if (run_first_.empty() || index != run_first_.back() + std::int32_t(size_ - run_start_.back()))
      run_first_.push_back(index), run_start_.push_back(size_);
    ++size_;
  }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  // The k-th index (k < size()).
  std::int32_t operator[](std::size_t k) const {
    const auto after = std::upper_bound(run_start_.begin(), run_start_.end(), k);
    const std::size_t run = std::size_t(after - run_start_.begin()) - 1;
    return run_first_[run] + std::int32_t(k - run_start_[run]);
  }

 private:
  std::vector<std::int32_t> run_first_;  // per run: its first index
  std::vector<std::size_t> run_start_;   // per run: how many indices come before it
  std::size_t size_ = 0;
};

// Which matches are allowed.
struct SearchConstraints {
  std::vector<std::uint8_t> source_valid;   // per source pixel: may be a patch center
  std::vector<std::uint8_t> target_active;  // per target pixel: is synthesized
  // Optional: target pixels whose matches neighbours may adopt (propagation,
  // coherence): the active ones plus hard-constrained pixels with a fixed
  // match. Empty = target_active.
  std::vector<std::uint8_t> target_matched;
  // Optional segment labels: a target pixel only matches sources with its label.
  std::vector<std::int32_t> source_segment, target_segment;
  // Extra cost per source center (usage terms); empty = none.
  std::vector<float> source_cost;
  // Valid source centers (indices), per segment label; filled by finalize().
  std::vector<SourceIndexRuns> valid_by_segment;
  const SourceLayout* layout = nullptr;  // for the frame links of video exemplars

  // Builds valid_by_segment; throws ValueError if a target segment has no source.
  void finalize();
  int segment_of_target(std::size_t i) const { return target_segment.empty() ? 0 : target_segment[i]; }
  int segment_of_source(std::size_t i) const { return source_segment.empty() ? 0 : source_segment[i]; }
  bool allowed(std::size_t source_index, int segment) const {
    return source_valid[source_index] && segment_of_source(source_index) == segment;
  }
  const std::vector<std::uint8_t>& matched() const { return target_matched.empty() ? target_active : target_matched; }
  float cost(std::size_t source_index) const { return source_cost.empty() ? 0.0f : source_cost[source_index]; }
};

// Extra candidates per target pixel (compressed rows: the candidates of
// target i are [begin[i], begin[i + 1])), tried after propagation.
struct CandidateList {
  std::vector<std::uint32_t> begin;  // target pixels + 1 entries
  std::vector<std::int32_t> x, y;    // atlas positions
  bool empty() const { return x.empty(); }
};

struct PatchMatchParams {
  int iterations = 4;
  std::uint64_t seed = 1;
  int threads = 0;
  int band_rows = 32;
  int random_tries_per_scale = 1;
  // The random search's widest window from the second sweep of a search on
  // (first_iteration + k > 0): at most this many pixels from the match; the
  // first sweep, and every sweep with 0, reach the whole source
  // (SynthesisOptions::search_radius).
  int search_radius = 0;
  const CandidateList* candidates = nullptr;
  // Terms that read the field (EnergyTerm::reads_field), with their context.
  std::vector<const EnergyTerm*> field_terms;
  const LevelContext* context = nullptr;
  // Index of the first iteration (scan direction and random stream): a search
  // split into single iterations, e.g. to refresh usage costs in between,
  // equals the unsplit one.
  int first_iteration = 0;
  // Optional: the active target pixels to improve (converged_pixels.hpp);
  // the others keep their match and still propagate it. Null = all.
  const std::vector<std::uint8_t>* searched = nullptr;
};

// Random valid source for every active target pixel, with distances.
void random_field(const PatchSpace& space, const SearchConstraints& constraints, OffsetField& field,
                  std::uint64_t seed, int threads);

// The same random sources as random_field(), only where `restart` (one
// byte per target pixel) is set; distances there +inf (refresh them). A warm
// start's disoccluded pixels, whose advected match is that of what hid them.
void restart_pixels(const PatchSpace& space, const SearchConstraints& constraints, OffsetField& field,
                    const std::vector<std::uint8_t>& restart, std::uint64_t seed);

// Recomputes field.dist for the current features (e.g. after voting changed B').
void refresh_distances(const PatchSpace& space, const SearchConstraints& constraints, OffsetField& field,
                       int threads);

// Moves matches that the constraints forbid (masked out, another segment)
// to a valid source chosen deterministically from the position, and zeroes
// inactive targets.
void legalize_field(const PatchSpace& space, const SearchConstraints& constraints, OffsetField& field);

// Improves `field` in place; only ever accepts cheaper matches.
void patchmatch(const PatchSpace& space, const SearchConstraints& constraints, OffsetField& field,
                const PatchMatchParams& params, std::uint64_t stream);

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

#pragma once
// Reversed NNF retrieval (Rosenberger et al. 2009; thesis §5.4.1), shared by
// uniform usage (uniform_usage.cpp) and StyLit's error budget
// (error_budget.cpp): each eligible source patch looks for its best target
// patch among those not yet assigned.
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "tempera/engine/energy_term.hpp"
#include "tempera/engine/parallel.hpp"
#include "tempera/engine/patchmatch.hpp"
#include "tempera/engine/rng.hpp"

namespace tempera {

struct ReversedRetrievalParams {
  int pm_iterations = 1;          // PatchMatch sweeps (in source space) per round; candidates persist across rounds
  double coverage_goal = 0.95;    // budget: stop once this fraction of targets is covered
  int max_rounds = 16;            // budget: at most this many rounds
  std::uint64_t seed = 1;
  int threads = 0;
};

constexpr std::int32_t kNoTarget = -1;
inline constexpr float kNoDistance = std::numeric_limits<float>::infinity();

struct Assignment {
  float dist;
  std::int32_t target;
  std::int32_t source;
  bool operator<(const Assignment& o) const {
    return dist < o.dist || (dist == o.dist && target < o.target);
  }
};

// Reversed NNF retrieval (Rosenberger et al. 2009; thesis §5.4.1): each
// eligible source patch looks for its best target patch among those not yet
// assigned. PatchMatch runs in source space: neighbours propagate their target
// candidates, random search explores around them, and a random unassigned
// target is tried too (it keeps the search alive when few targets remain).
class ReversedRetrieval {
 public:
  ReversedRetrieval(const PatchSpace& space, const SearchConstraints& cons, OffsetField& nnf,
                    const ReversedRetrievalParams& params, std::uint64_t stream)
      : space_(space), cons_(cons), nnf_(nnf), params_(params), stream_(stream),
        sw_(space.source->width), sh_(space.source->height), tw_(nnf.width), th_(nnf.height),
        open_(cons.target_active), eligible_(std::size_t(sw_) * sh_, 0),
        search_(std::size_t(sw_) * sh_, kPropagate),
        candidate_(std::size_t(sw_) * sh_, kNoTarget), candidate_dist_(std::size_t(sw_) * sh_, kNoDistance),
        best_source_(std::size_t(tw_) * th_) {
    for (std::uint8_t a : open_) active_ += a != 0;
  }

  std::vector<std::uint8_t>& eligible() { return eligible_; }
  // Per target, a source it was matched to before (atlas index; null: none):
  // seeds like the forward match's.
  void set_earlier_sources(const std::vector<std::int32_t>* earlier) {
    earlier_ = earlier && earlier->size() == open_.size() ? earlier : nullptr;
  }
  std::size_t active() const { return active_; }
  std::size_t assigned_count() const { return assigned_count_; }
  const std::vector<std::int32_t>& candidate() const { return candidate_; }
  const std::vector<float>& candidate_dist() const { return candidate_dist_; }
  // Sources seeded with a random target so far (each searched over the whole
  // frame: the costly part of a round).
  std::size_t wide_searches() const { return wide_searches_; }

  // One round of retrieval: fills candidates for eligible sources and picks
  // the best source of each target they reach (the round's winners).
  void search(int round_index) {
    collect_unassigned();
    seed_candidates(round_index);
    for (int it = 0; it < params_.pm_iterations; ++it) sweep(round_index, it);
    resolve_collisions();
  }

  // The last search's winners, collision-free (one source per target), in
  // target order; f may assign() them. Read in place: a list of a round's
  // winners was up to 12 bytes a target at the peak of the solve.
  template <class F>
  void for_each_winner(F&& f) const {
    for (std::size_t q = 0; q < best_source_.size(); ++q) {
      const std::uint32_t p = best_source_[q].load(std::memory_order_relaxed);
      if (p != kNoSource) f(Assignment{candidate_dist_[p], std::int32_t(q), std::int32_t(p)});
    }
  }

  // search(), then its winners as a list (to sort them).
  std::vector<Assignment> round(int round_index) {
    search(round_index);
    std::vector<Assignment> out;
    out.reserve(std::size_t(std::count_if(best_source_.begin(), best_source_.end(), [](const auto& b) {
      return b.load(std::memory_order_relaxed) != kNoSource;
    })));
    for_each_winner([&](const Assignment& a) { out.push_back(a); });
    return out;
  }

  void assign(const Assignment& a) {
    nnf_.x[a.target] = a.source % sw_;
    nnf_.y[a.target] = a.source / sw_;
    nnf_.dist[a.target] = a.dist / border_scale(a.target % tw_, a.target / tw_);
    open_[a.target] = 0;
    // The source keeps the target it won, now closed, as the centre of its
    // next round's local search, like a source that lost its candidate: its
    // best open target is most often next to the one it filled.
    candidate_dist_[a.source] = kNoDistance;
    ++assigned_count_;
  }

 private:
  // Target patches at the frame border are clipped, so their raw distances
  // sum fewer pixels and would look like bargains to every source patch.
  // Reversed retrieval compares distances across targets, so it scales them
  // to a whole patch.
  float border_scale(int qx, int qy) const {
    const int r = space_.radius;
    const int w = std::min(r, tw_ - 1 - qx) + std::min(r, qx) + 1;
    const int h = std::min(r, th_ - 1 - qy) + std::min(r, qy) + 1;
    return float((2 * r + 1) * (2 * r + 1)) / float(w * h);
  }

  float scaled_distance(int sx, int sy, int qx, int qy, float cutoff) const {
    const float scale = border_scale(qx, qy);
    return scale * patch_distance(space_, sx, sy, qx, qy, cutoff / scale);
  }

  bool open_target(int qx, int qy, int segment) const {
    if (qx < 0 || qy < 0 || qx >= tw_ || qy >= th_) return false;
    const std::size_t q = std::size_t(qy) * tw_ + qx;
    return open_[q] && cons_.segment_of_target(q) == segment;
  }

  void collect_unassigned() {
    unassigned_.resize(cons_.valid_by_segment.size());
    for (auto& list : unassigned_) list.clear();  // keeps the capacity for the next round
    for (std::size_t q = 0; q < open_.size(); ++q)
      if (open_[q]) unassigned_[cons_.segment_of_target(q)].push_back(std::int32_t(q));
  }

  // Keeps still-open candidates, adopts targets whose forward match (or
  // earlier match) is this source (good pairs known), else picks at random.
  // Only the random picks need the wide random search of the sweep; a source
  // whose candidate was closed (won by another source, or by itself in an
  // earlier round) searches around that target (its best open one is most
  // often near it), the others are refined by propagation alone.
  void seed_candidates(int round_index) {
    parallel_for(sh_, params_.threads, [&](int sy) {
      for (std::size_t p = std::size_t(sy) * sw_, end = p + sw_; p < end; ++p) {
        if (!eligible_[p]) {
          candidate_[p] = kNoTarget;
          candidate_dist_[p] = kNoDistance;
        } else if (candidate_[p] != kNoTarget && !open_[candidate_[p]]) {
          candidate_dist_[p] = kNoDistance;  // lost: any open target is better
        }
        search_[p] = kPropagate;
      }
    });
    for (const auto& list : unassigned_) {
      for (std::int32_t q : list) {
        const std::size_t p = std::size_t(nnf_.y[q]) * sw_ + nnf_.x[q];
        const float d = nnf_.dist[q] * border_scale(q % tw_, q / tw_);
        if (eligible_[p] && d < candidate_dist_[p]) {
          candidate_[p] = q;
          candidate_dist_[p] = d;
        }
      }
    }
    if (earlier_) adopt_earlier();
    parallel_for(sh_, params_.threads, [&](int sy) {
      for (int sx = 0; sx < sw_; ++sx) {
        const std::size_t p = std::size_t(sy) * sw_ + sx;
        if (!eligible_[p] || (candidate_[p] != kNoTarget && open_[candidate_[p]])) continue;
        if (candidate_[p] != kNoTarget) {  // lost, and adopted nothing
          search_[p] = kLocal;
          continue;
        }
        const auto& list = unassigned_[cons_.segment_of_source(p)];
        if (list.empty()) continue;
        Rng rng(params_.seed, mix64(stream_ * 7919 + round_index) ^ p);
        const std::int32_t q = list[rng.below(int(list.size()))];
        candidate_[p] = q;
        candidate_dist_[p] = scaled_distance(sx, sy, q % tw_, q / tw_, kNoDistance);
        search_[p] = kWide;
      }
    });
    wide_searches_ += std::size_t(std::count(search_.begin(), search_.end(), kWide));
  }

  // Each eligible source adopts the best open target that was matched to it
  // before. Where those matches came from the previous reassignment they
  // spread over most sources, whereas the search since has pulled the forward
  // matches back onto a few favourites: so most sources start near their best
  // target and skip the wide search.
  void adopt_earlier() {
    const auto& earlier = *earlier_;
    // The distances are computed in parallel a band of rows at a time and
    // adopted in target order (a tie keeps the lower target): a band's
    // distances are held, not a frame's (4 bytes a target at the peak of the
    // still's memory).
    constexpr int kBandRows = 64;
    std::vector<float> band_dist(std::size_t(std::min(kBandRows, th_)) * tw_);
    for (int y0 = 0; y0 < th_; y0 += kBandRows) {
      const int rows = std::min(kBandRows, th_ - y0);
      parallel_for(rows, params_.threads, [&](int row) {
        const int qy = y0 + row;
        for (int qx = 0; qx < tw_; ++qx) {
          const std::size_t q = std::size_t(qy) * tw_ + qx;
          const std::int32_t p = earlier[q];
          const bool usable = open_[q] && p >= 0 && p < std::int32_t(eligible_.size()) && eligible_[p] &&
                              cons_.segment_of_source(std::size_t(p)) == cons_.segment_of_target(q);
          band_dist[std::size_t(row) * tw_ + qx] =
              usable ? scaled_distance(p % sw_, p / sw_, qx, qy, kNoDistance) : kNoDistance;
        }
      });
      const std::size_t first = std::size_t(y0) * tw_;
      for (std::size_t i = 0; i < std::size_t(rows) * tw_; ++i) {
        const std::int32_t p = earlier[first + i];
        if (band_dist[i] < kNoDistance && band_dist[i] < candidate_dist_[p]) {
          candidate_[p] = std::int32_t(first + i);
          candidate_dist_[p] = band_dist[i];
        }
      }
    }
  }

  // Always inlined, as Matcher::prefetch (patchmatch.cpp): GCC deletes calls
  // to a function that only prefetches.
  [[gnu::always_inline]] inline void prefetch_target(int qx, int qy) const {
    if (qx < 0 || qy < 0 || qx >= tw_ || qy >= th_) return;
    __builtin_prefetch(&open_[std::size_t(qy) * tw_ + qx]);
    const int r = space_.radius;
    const int x0 = std::max(0, qx - r), bytes = (2 * r + 1) * space_.target->bytes_per_pixel();
    for (int dy = -r; dy <= std::min(r, 1 - r); ++dy) {
      if (qy + dy < 0 || qy + dy >= th_) continue;
      const char* row = space_.target->pixel_bytes(x0, qy + dy);
      for (int off = 0; off < bytes; off += 64) __builtin_prefetch(row + off);
    }
  }

  void try_target(int sx, int sy, int qx, int qy, int segment, std::int32_t& best, float& best_dist) const {
    if (!open_target(qx, qy, segment)) return;
    const std::int32_t q = qy * tw_ + qx;
    if (q == best) return;
    const float d = scaled_distance(sx, sy, qx, qy, best_dist);
    if (d < best_dist) {
      best = q;
      best_dist = d;
    }
  }

  void sweep(int round_index, int iteration) {
    const int band_rows = 32, bands = (sh_ + band_rows - 1) / band_rows;
    const bool forward = iteration % 2 == 0;
    const int step = forward ? 1 : -1;
    const int max_radius = std::max(tw_, th_);
    // A band propagates from the row before it (in sweep order) as it was
    // before the sweep, so that no band reads another's progress.
    std::vector<std::int32_t> edge(std::size_t(bands) * sw_, kNoTarget);
    for (int band = 0; band < bands; ++band) {
      const int ey = forward ? band * band_rows - 1 : std::min(sh_, (band + 1) * band_rows);
      if (ey >= 0 && ey < sh_)
        std::copy_n(candidate_.begin() + std::ptrdiff_t(ey) * sw_, sw_, edge.begin() + std::ptrdiff_t(band) * sw_);
    }
    parallel_for(bands, params_.threads, [&](int band) {
      const int y0 = band * band_rows, y1 = std::min(sh_, y0 + band_rows);
      Rng rng(params_.seed, mix64(stream_ * 104729 + round_index * 131 + iteration) ^ std::uint64_t(band));
      for (int row = 0; row < y1 - y0; ++row) {
        const int sy = forward ? y0 + row : y1 - 1 - row;
        for (int col = 0; col < sw_; ++col) {
          const int sx = forward ? col : sw_ - 1 - col;
          const std::size_t p = std::size_t(sy) * sw_ + sx;
          if (!eligible_[p] || candidate_[p] == kNoTarget) continue;
          const int segment = cons_.segment_of_source(p);
          // The random draws do not depend on the search, so they come first:
          // the offsets of the random search (around the propagated best)
          // and a random open target, whose list slot is then fetched while
          // propagation runs.
          int off[64], n = 0;
          const int first_radius = search_[p] == kWide ? max_radius : search_[p] == kLocal ? kLocalRadius : 0;
          for (int r = first_radius; r >= 1 && n < 64; r /= 2, n += 2) {
            off[n] = rng.between(-r, r);
            off[n + 1] = rng.between(-r, r);
          }
          const auto& list = unassigned_[segment];
          const std::int32_t* open_pick = list.empty() ? nullptr : &list[rng.below(int(list.size()))];
          if (open_pick) __builtin_prefetch(open_pick);
          std::int32_t best = candidate_[p];
          float best_dist = candidate_dist_[p];
          const int nbr[2][2] = {{-step, 0}, {0, -step}};
          for (const auto& d : nbr) {
            const int nx = sx + d[0], ny = sy + d[1];
            if (nx < 0 || ny < 0 || nx >= sw_ || ny >= sh_) continue;
            const std::size_t np = std::size_t(ny) * sw_ + nx;
            const std::int32_t nq = (ny >= y0 && ny < y1) ? candidate_[np] : edge[std::size_t(band) * sw_ + nx];
            if (nq == kNoTarget) continue;
            // The neighbour's target shifted back by d, with d rotated from
            // source into target space.
            float ox = float(d[0]), oy = float(d[1]);
            if (space_.rotated()) rotate_offset(-space_.rotation(nx, ny, nq % tw_, nq / tw_), ox, oy, ox, oy);
            try_target(sx, sy, nq % tw_ - int(std::lround(ox)), nq / tw_ - int(std::lround(oy)), segment, best,
                       best_dist);
          }
          // Random search around the propagated best, then the random open
          // target; all are prefetched before the first is tested (see
          // patchmatch.cpp).
          const std::int32_t pick = open_pick ? *open_pick : kNoTarget;
          if (open_pick) prefetch_target(pick % tw_, pick / tw_);
          const int bx = best % tw_, by = best / tw_;
          for (int k = 0; k < n; k += 2) prefetch_target(bx + off[k], by + off[k + 1]);
          for (int k = 0; k < n; k += 2) try_target(sx, sy, bx + off[k], by + off[k + 1], segment, best, best_dist);
          if (open_pick) try_target(sx, sy, pick % tw_, pick / tw_, segment, best, best_dist);
          if (best_dist == kNoDistance) best = kNoTarget;  // lost, and found nothing open
          candidate_[p] = best;
          candidate_dist_[p] = best_dist;
        }
      }
    });
  }

  // Best source per target, in parallel: an atomic minimum in the order of
  // (distance, source index), so the winner does not depend on thread timing.
  // The atomic holds the source alone (4 bytes a target, not 8 with the
  // distance): candidate distances do not change while collisions resolve.
  void resolve_collisions() {
    auto& best = best_source_;
    parallel_for(th_, params_.threads, [&](int qy) {
      for (std::size_t q = std::size_t(qy) * tw_, end = q + tw_; q < end; ++q)
        best[q].store(kNoSource, std::memory_order_relaxed);
    });
    parallel_for(sh_, params_.threads, [&](int sy) {
      for (std::size_t p = std::size_t(sy) * sw_, end = p + sw_; p < end; ++p) {
        const std::int32_t q = candidate_[p];
        if (!eligible_[p] || q == kNoTarget || !open_[q]) continue;
        std::uint32_t cur = best[q].load(std::memory_order_relaxed);
        while (beats(p, cur) && !best[q].compare_exchange_weak(cur, std::uint32_t(p), std::memory_order_relaxed)) {
        }
      }
    });
  }

  bool beats(std::size_t p, std::uint32_t holder) const {
    if (holder == kNoSource) return true;
    const float d = candidate_dist_[p], h = candidate_dist_[holder];
    return d < h || (d == h && p < holder);
  }

  const PatchSpace& space_;
  const SearchConstraints& cons_;
  OffsetField& nnf_;
  const ReversedRetrievalParams& params_;
  std::uint64_t stream_;
  int sw_, sh_, tw_, th_;
  // open_: active and not yet assigned, one byte a target, so that testing a
  // random candidate costs one cache miss, not two.
  std::vector<std::uint8_t> open_, eligible_;
  // A source's random search in this round's sweep: none (propagation and a
  // random open target only), around a lost target, or over the whole frame.
  enum Search : std::uint8_t { kPropagate, kLocal, kWide };
  static constexpr int kLocalRadius = 8;  // 8, 4, 2, 1: 4 offsets, against 10 for a 600-pixel frame
  std::vector<Search> search_;
  std::vector<std::int32_t> candidate_;
  std::vector<float> candidate_dist_;
  std::vector<std::vector<std::int32_t>> unassigned_;
  const std::vector<std::int32_t>* earlier_ = nullptr;
  static constexpr std::uint32_t kNoSource = ~0u;
  std::vector<std::atomic<std::uint32_t>> best_source_;  // resolve_collisions' per-target minimum, kept across rounds
  std::size_t active_ = 0, assigned_count_ = 0, wide_searches_ = 0;
};

}  // namespace tempera

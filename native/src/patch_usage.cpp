#include "tempera/patch_usage.hpp"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

#include "tempera/error.hpp"
#include "tempera/parallel.hpp"
#include "tempera/rng.hpp"

namespace tempera {

PatchUsage parse_patch_usage(const std::string& name) {
  if (name == "none") return PatchUsage::None;
  if (name == "penalty") return PatchUsage::Penalty;
  if (name == "uniform") return PatchUsage::Uniform;
  if (name == "budget") return PatchUsage::Budget;
  throw ValueError(concat("unknown patch usage '", name, "' (choose none, penalty, uniform or budget)"));
}

const char* patch_usage_name(PatchUsage usage) {
  switch (usage) {
    case PatchUsage::None: return "none";
    case PatchUsage::Penalty: return "penalty";
    case PatchUsage::Uniform: return "uniform";
    case PatchUsage::Budget: return "budget";
  }
  return "?";
}

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr std::int32_t kNone = -1;

struct Assignment {
  float dist;
  std::int32_t target;
  std::int32_t source;
  bool operator<(const Assignment& o) const { return std::tie(dist, target) < std::tie(o.dist, o.target); }
};

// Reversed NNF retrieval (Rosenberger et al. 2009; thesis §5.4.1): each
// eligible source patch looks for its best target patch among those not yet
// assigned. PatchMatch runs in source space: neighbours propagate their target
// candidates, random search explores around them, and a random unassigned
// target is tried too (it keeps the search alive when few targets remain).
class ReversedRetrieval {
 public:
  ReversedRetrieval(const PatchSpace& space, const SearchConstraints& cons, Nnf& nnf,
                    const ReversedRetrievalParams& params, std::uint64_t stream)
      : space_(space), cons_(cons), nnf_(nnf), params_(params), stream_(stream),
        sw_(space.source->width), sh_(space.source->height), tw_(nnf.width), th_(nnf.height),
        assigned_(std::size_t(tw_) * th_, 0), eligible_(std::size_t(sw_) * sh_, 0),
        wide_search_(std::size_t(sw_) * sh_, 0),
        candidate_(std::size_t(sw_) * sh_, kNone), candidate_dist_(std::size_t(sw_) * sh_, kInf) {
    for (std::size_t i = 0; i < assigned_.size(); ++i)
      if (cons.target_active[i]) ++active_;
  }

  std::vector<std::uint8_t>& eligible() { return eligible_; }
  std::size_t active() const { return active_; }
  std::size_t assigned_count() const { return assigned_count_; }
  const std::vector<std::int32_t>& candidate() const { return candidate_; }
  const std::vector<float>& candidate_dist() const { return candidate_dist_; }

  // One round of retrieval: fills candidates for eligible sources and returns
  // the collision-free (best source per target) assignments, in target order.
  std::vector<Assignment> round(int round_index) {
    collect_unassigned();
    seed_candidates(round_index);
    for (int it = 0; it < params_.pm_iterations; ++it) sweep(round_index, it);
    return resolve_collisions();
  }

  void assign(const Assignment& a) {
    nnf_.x[a.target] = a.source % sw_;
    nnf_.y[a.target] = a.source / sw_;
    nnf_.dist[a.target] = a.dist / border_scale(a.target % tw_, a.target / tw_);
    assigned_[a.target] = 1;
    candidate_[a.source] = kNone;
    candidate_dist_[a.source] = kInf;
    ++assigned_count_;
  }

  bool is_assigned(std::size_t target) const { return assigned_[target] != 0; }

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
    return cons_.target_active[q] && !assigned_[q] && cons_.segment_of_target(q) == segment;
  }

  void collect_unassigned() {
    unassigned_.assign(cons_.valid_by_segment.size(), {});
    for (std::size_t q = 0; q < assigned_.size(); ++q)
      if (cons_.target_active[q] && !assigned_[q]) unassigned_[cons_.segment_of_target(q)].push_back(std::int32_t(q));
  }

  // Keeps still-open candidates, adopts targets whose forward match is this
  // source (the forward NNF already knows good pairs), else picks at random.
  // Only the random picks need the wide random search of the sweep; the
  // others are refined by propagation alone (half the cost of a round).
  void seed_candidates(int round_index) {
    for (std::size_t p = 0; p < candidate_.size(); ++p) {
      if (!eligible_[p] || (candidate_[p] != kNone && assigned_[candidate_[p]])) {
        candidate_[p] = kNone;
        candidate_dist_[p] = kInf;
      }
      wide_search_[p] = 0;
    }
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
    parallel_for(sh_, params_.threads, [&](int sy) {
      for (int sx = 0; sx < sw_; ++sx) {
        const std::size_t p = std::size_t(sy) * sw_ + sx;
        if (!eligible_[p] || candidate_[p] != kNone) continue;
        const auto& list = unassigned_[cons_.segment_of_source(p)];
        if (list.empty()) continue;
        Rng rng(params_.seed, mix64(stream_ * 7919 + round_index) ^ p);
        const std::int32_t q = list[rng.below(int(list.size()))];
        candidate_[p] = q;
        candidate_dist_[p] = scaled_distance(sx, sy, q % tw_, q / tw_, kInf);
        wide_search_[p] = 1;
      }
    });
  }

  void prefetch_target(int qx, int qy) const {
    if (qx < 0 || qy < 0 || qx >= tw_ || qy >= th_) return;
    const int r = space_.radius;
    const int x0 = std::max(0, qx - r), bytes = (2 * r + 1) * space_.target->stride * int(sizeof(float));
    for (int dy = -r; dy <= std::min(r, 1 - r); ++dy) {
      if (qy + dy < 0 || qy + dy >= th_) continue;
      const char* row = reinterpret_cast<const char*>(space_.target->pixel(x0, qy + dy));
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
    const std::vector<std::int32_t> snapshot = candidate_;
    const bool forward = iteration % 2 == 0;
    const int step = forward ? 1 : -1;
    const int max_radius = std::max(tw_, th_);
    parallel_for(bands, params_.threads, [&](int band) {
      const int y0 = band * band_rows, y1 = std::min(sh_, y0 + band_rows);
      Rng rng(params_.seed, mix64(stream_ * 104729 + round_index * 131 + iteration) ^ std::uint64_t(band));
      for (int row = 0; row < y1 - y0; ++row) {
        const int sy = forward ? y0 + row : y1 - 1 - row;
        for (int col = 0; col < sw_; ++col) {
          const int sx = forward ? col : sw_ - 1 - col;
          const std::size_t p = std::size_t(sy) * sw_ + sx;
          if (!eligible_[p] || candidate_[p] == kNone) continue;
          const int segment = cons_.segment_of_source(p);
          std::int32_t best = candidate_[p];
          float best_dist = candidate_dist_[p];
          const int nbr[2][2] = {{-step, 0}, {0, -step}};
          for (const auto& d : nbr) {
            const int nx = sx + d[0], ny = sy + d[1];
            if (nx < 0 || ny < 0 || nx >= sw_ || ny >= sh_) continue;
            const std::size_t np = std::size_t(ny) * sw_ + nx;
            const std::int32_t nq = (ny >= y0 && ny < y1) ? candidate_[np] : snapshot[np];
            if (nq == kNone) continue;
            // The neighbour's target shifted back by d, with d rotated from
            // source into target space.
            float ox = float(d[0]), oy = float(d[1]);
            if (space_.rotated()) rotate_offset(-space_.rotation(nx, ny, nq % tw_, nq / tw_), ox, oy, ox, oy);
            try_target(sx, sy, nq % tw_ - int(std::lround(ox)), nq / tw_ - int(std::lround(oy)), segment, best,
                       best_dist);
          }
          // Random search around the propagated best; candidates are drawn
          // first and prefetched (see patchmatch.cpp).
          int cand[64], n = 0;
          for (int r = wide_search_[p] ? max_radius : 0; r >= 1 && n < 64; r /= 2, n += 2) {
            cand[n] = best % tw_ + rng.between(-r, r);
            cand[n + 1] = best / tw_ + rng.between(-r, r);
            prefetch_target(cand[n], cand[n + 1]);
          }
          for (int k = 0; k < n; k += 2) try_target(sx, sy, cand[k], cand[k + 1], segment, best, best_dist);
          const auto& list = unassigned_[segment];
          if (!list.empty()) {
            const std::int32_t q = list[rng.below(int(list.size()))];
            try_target(sx, sy, q % tw_, q / tw_, segment, best, best_dist);
          }
          candidate_[p] = best;
          candidate_dist_[p] = best_dist;
        }
      }
    });
  }

  // Best source per target, in parallel: an atomic minimum over (distance
  // bits, source index), so the winner does not depend on thread timing.
  std::vector<Assignment> resolve_collisions() const {
    std::vector<std::atomic<std::uint64_t>> best(assigned_.size());
    for (auto& b : best) b.store(~0ull, std::memory_order_relaxed);
    parallel_for(sh_, params_.threads, [&](int sy) {
      for (std::size_t p = std::size_t(sy) * sw_, end = p + sw_; p < end; ++p) {
        const std::int32_t q = candidate_[p];
        if (!eligible_[p] || q == kNone || assigned_[q]) continue;
        std::uint32_t bits;
        std::memcpy(&bits, &candidate_dist_[p], sizeof bits);  // >= 0: bits order like values
        const std::uint64_t key = (std::uint64_t(bits) << 32) | std::uint64_t(p);
        std::uint64_t cur = best[q].load(std::memory_order_relaxed);
        while (key < cur && !best[q].compare_exchange_weak(cur, key, std::memory_order_relaxed)) {
        }
      }
    });
    std::vector<Assignment> out;
    for (std::size_t q = 0; q < best.size(); ++q) {
      const std::uint64_t key = best[q].load(std::memory_order_relaxed);
      if (key == ~0ull) continue;
      const std::int32_t p = std::int32_t(key & 0xFFFFFFFFull);
      out.push_back({candidate_dist_[p], std::int32_t(q), p});
    }
    return out;
  }

  const PatchSpace& space_;
  const SearchConstraints& cons_;
  Nnf& nnf_;
  const ReversedRetrievalParams& params_;
  std::uint64_t stream_;
  int sw_, sh_, tw_, th_;
  std::vector<std::uint8_t> assigned_, eligible_, wide_search_;
  std::vector<std::int32_t> candidate_;
  std::vector<float> candidate_dist_;
  std::vector<std::vector<std::int32_t>> unassigned_;
  std::size_t active_ = 0, assigned_count_ = 0;
};

// Hyperbola f(x) = 1 / (a - b x) fitted to (x, y) by Gauss-Newton, starting
// from the weighted linear fit of 1/y = a - b x. Returns {a, b}.
std::pair<double, double> fit_hyperbola(const std::vector<double>& xs, const std::vector<double>& ys) {
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const double w = ys[i] * ys[i], inv = 1.0 / ys[i];  // d(1/y) = dy / y^2
    sw += w, sx += w * xs[i], sy += w * inv, sxx += w * xs[i] * xs[i], sxy += w * xs[i] * inv;
  }
  const double det = sw * sxx - sx * sx;
  if (std::abs(det) < 1e-12) return {1.0, 0.0};
  double slope = (sw * sxy - sx * sy) / det;
  double a = (sy - slope * sx) / sw, b = -slope;
  for (int it = 0; it < 20; ++it) {
    double jtj[3] = {0, 0, 0}, jtr[2] = {0, 0};
    for (std::size_t i = 0; i < xs.size(); ++i) {
      const double den = a - b * xs[i];
      if (den <= 1e-9) return {a, b};
      const double f = 1.0 / den, ja = -f * f, jb = xs[i] * f * f, r = ys[i] - f;
      jtj[0] += ja * ja, jtj[1] += ja * jb, jtj[2] += jb * jb;
      jtr[0] += ja * r, jtr[1] += jb * r;
    }
    const double d = jtj[0] * jtj[2] - jtj[1] * jtj[1];
    if (std::abs(d) < 1e-18) break;
    double da = (jtj[2] * jtr[0] - jtj[1] * jtr[1]) / d, db = (jtj[0] * jtr[1] - jtj[1] * jtr[0]) / d;
    // Keep the pole to the right of the data (a - b x > 0 on [0, 1]).
    double na = a + da, nb = b + db;
    for (int h = 0; h < 30 && (na <= 0 || na - nb <= 1e-6); ++h) na = a + (da *= 0.5), nb = b + (db *= 0.5);
    if (na <= 0 || na - nb <= 1e-6) break;
    a = na, b = nb;
    if (std::abs(da) + std::abs(db) < 1e-9) break;
  }
  return {a, b};
}

}  // namespace

std::size_t error_knee(const std::vector<float>& sorted) {
  const std::size_t n = sorted.size();
  if (n < 8) return n;
  const double top = sorted.back();
  if (!(top > 0)) return n;
  // Normalized axes on an even subsample: x in [0, 1], y = error / max error.
  const std::size_t m = std::min<std::size_t>(n, 1024);
  std::vector<double> xs(m), ys(m);
  for (std::size_t i = 0; i < m; ++i) {
    const std::size_t j = i * (n - 1) / (m - 1);
    xs[i] = double(j) / double(n - 1);
    ys[i] = std::max(double(sorted[j]) / top, 1e-4);
  }
  // The paper's knee: where the fitted hyperbola's slope reaches 1.
  const auto [a, b] = fit_hyperbola(xs, ys);
  double knee = 1.0;
  if (b > 1e-9) knee = std::clamp((a - std::sqrt(b)) / b, 0.0, 1.0);
  // A hyperbola cannot follow a step (two populations of errors, e.g. good
  // matches and forced ones): there the fit flattens and its knee slides to the
  // end. The first point where the smoothed empirical slope reaches 1 catches
  // the step; a true hyperbola crosses slope 1 at the same place.
  const std::size_t w = std::max<std::size_t>(2, m / 64);
  for (std::size_t i = 0; i + w < m; ++i) {
    const double slope = (ys[i + w] - ys[i]) / (xs[i + w] - xs[i]);
    if (slope >= 1.0) {
      knee = std::min(knee, xs[i + w / 2]);
      break;
    }
  }
  return std::clamp<std::size_t>(std::size_t(std::ceil(knee * double(n - 1))), 1, n);
}

ReversedRetrievalStats retrieve_uniform(const PatchSpace& space, const SearchConstraints& cons, Nnf& nnf,
                                        const ReversedRetrievalParams& params, std::uint64_t stream) {
  const int sw = space.source->width;
  ReversedRetrieval rr(space, cons, nnf, params, stream);
  // Per segment: K = |X_s| / |Z_s| uses for every source, R of them once more.
  const std::size_t segments = cons.valid_by_segment.size();
  std::vector<std::size_t> targets(segments, 0), quota(segments, 0), extra(segments, 0);
  for (std::size_t q = 0; q < cons.target_active.size(); ++q)
    if (cons.target_active[q]) ++targets[cons.segment_of_target(q)];
  for (std::size_t s = 0; s < segments; ++s) {
    const std::size_t z = cons.valid_by_segment[s].size();
    if (z == 0) continue;
    quota[s] = targets[s] / z;
    extra[s] = targets[s] % z;
  }
  std::vector<std::uint32_t> uses(std::size_t(sw) * space.source->height, 0);
  auto can_take = [&](std::size_t p) {
    const int s = cons.segment_of_source(p);
    return uses[p] < quota[s] || (uses[p] == quota[s] && extra[s] > 0);
  };
  auto take = [&](const Assignment& a) {
    const int s = cons.segment_of_source(a.source);
    if (uses[a.source] == quota[s]) --extra[s];
    ++uses[a.source];
    rr.assign(a);
  };
  auto refresh_eligible = [&] {
    for (std::size_t p = 0; p < uses.size(); ++p) rr.eligible()[p] = cons.source_valid[p] && can_take(p);
  };
  ReversedRetrievalStats stats;
  const int max_rounds = 64;  // then a greedy fill finishes the last few
  while (rr.assigned_count() < rr.active() && stats.rounds < max_rounds) {
    refresh_eligible();
    auto winners = rr.round(stats.rounds++);
    std::sort(winners.begin(), winners.end());  // best first: counters fill with the best pairs
    std::size_t taken = 0;
    for (const auto& a : winners)
      if (can_take(a.source)) take(a), ++taken;
    if (taken == 0) break;
  }
  stats.covered = double(rr.assigned_count()) / double(std::max<std::size_t>(1, rr.active()));
  // Greedy fill: each remaining target takes the best of a deterministic sample
  // of sources that still have capacity (its forward match first).
  if (rr.assigned_count() < rr.active()) {
    refresh_eligible();
    std::vector<std::vector<std::int32_t>> open(segments);
    for (std::size_t p = 0; p < uses.size(); ++p)
      if (rr.eligible()[p]) open[cons.segment_of_source(p)].push_back(std::int32_t(p));
    std::vector<std::uint8_t> pruned(segments, 0);
    Rng rng(params.seed, mix64(stream) ^ 0xF111ull);
    for (std::size_t q = 0; q < cons.target_active.size(); ++q) {
      if (!cons.target_active[q] || rr.is_assigned(q)) continue;
      auto& pool = open[cons.segment_of_target(q)];
      const int tx = int(q % nnf.width), ty = int(q / nnf.width);
      std::size_t best_slot = pool.size();
      float best = kInf;
      for (int k = 0; k < 33 && !pool.empty(); ++k) {
        const std::size_t slot = rng.below(int(pool.size()));
        const std::int32_t p = pool[slot];
        const float d = patch_distance(space, p % sw, p / sw, tx, ty, best);
        if (d < best) best = d, best_slot = slot;
      }
      if (best_slot == pool.size()) throw ValueError("internal: uniform retrieval ran out of source capacity");
      const std::int32_t p = pool[best_slot];
      take({best, std::int32_t(q), p});
      if (!can_take(p)) pool[best_slot] = pool.back(), pool.pop_back();
      // When the last extra use of a segment is spent, sources at K are full.
      const int s = cons.segment_of_source(p);
      if (extra[s] == 0 && !pruned[s]++)
        pool.erase(std::remove_if(pool.begin(), pool.end(), [&](std::int32_t o) { return !can_take(o); }),
                   pool.end());
    }
  }
  return stats;
}

ReversedRetrievalStats retrieve_with_budget(const PatchSpace& space, const SearchConstraints& cons, Nnf& nnf,
                                            const ReversedRetrievalParams& params, std::uint64_t stream) {
  ReversedRetrieval rr(space, cons, nnf, params, stream);
  rr.eligible() = cons.source_valid;
  ReversedRetrievalStats stats;
  while (stats.rounds < params.max_rounds &&
         double(rr.assigned_count()) < params.coverage_goal * double(rr.active())) {
    const auto winners = rr.round(stats.rounds++);
    // The knee of this round's sorted candidate errors.
    std::vector<float> errors;
    for (std::size_t p = 0; p < rr.candidate().size(); ++p)
      if (rr.eligible()[p] && rr.candidate()[p] != kNone) errors.push_back(rr.candidate_dist()[p]);
    if (errors.empty()) break;
    std::sort(errors.begin(), errors.end());
    const float knee_error = errors[error_knee(errors) - 1];
    // Sources whose best open target is already past the knee only get worse
    // as targets fill up: retire them.
    for (std::size_t p = 0; p < rr.candidate().size(); ++p)
      if (rr.eligible()[p] && rr.candidate()[p] != kNone && rr.candidate_dist()[p] > knee_error)
        rr.eligible()[p] = 0;
    // The budget T is the sum of all candidate errors below the knee; the
    // winners below the knee are a subset of those candidates, so taking all of
    // them keeps the total under T (thesis eq. 8.4).
    std::size_t taken = 0;
    for (const auto& a : winners) {
      if (a.dist > knee_error) continue;
      rr.assign(a);
      ++taken;
    }
    if (taken == 0) break;
  }
  stats.covered = double(rr.assigned_count()) / double(std::max<std::size_t>(1, rr.active()));
  return stats;  // targets not covered keep their forward match
}

std::vector<float> occurrence_penalty(const Nnf& nnf, const SearchConstraints& cons, int source_width, float weight) {
  std::vector<float> uses(cons.source_valid.size(), 0.0f);
  std::vector<float> dists;
  for (std::size_t q = 0; q < cons.target_active.size(); ++q) {
    if (!cons.target_active[q]) continue;
    uses[std::size_t(nnf.y[q]) * source_width + nnf.x[q]] += 1.0f;
    dists.push_back(nnf.dist[q]);
  }
  std::size_t valid = 0;
  for (auto v : cons.source_valid) valid += v;
  if (dists.empty() || valid == 0) return uses;
  std::nth_element(dists.begin(), dists.begin() + dists.size() / 2, dists.end());
  const float typical = std::max(dists[dists.size() / 2], 1e-6f);
  const float fair = float(dists.size()) / float(valid);  // omega: uses per source if uniform
  for (auto& u : uses) u = weight * typical * u / fair;
  return uses;
}

double source_coverage(const Nnf& nnf, const SearchConstraints& cons, int source_width) {
  std::vector<std::uint8_t> used(cons.source_valid.size(), 0);
  for (std::size_t q = 0; q < cons.target_active.size(); ++q)
    if (cons.target_active[q]) used[std::size_t(nnf.y[q]) * source_width + nnf.x[q]] = 1;
  std::size_t valid = 0, hit = 0;
  for (std::size_t p = 0; p < used.size(); ++p) valid += cons.source_valid[p], hit += used[p] && cons.source_valid[p];
  return valid ? double(hit) / double(valid) : 0.0;
}

}  // namespace tempera

#include "tempera/patchmatch.hpp"

#include <algorithm>
#include <limits>

#include "tempera/error.hpp"
#include "tempera/parallel.hpp"
#include "tempera/rng.hpp"

namespace tempera {

void SearchConstraints::finalize() {
  int segments = 1;
  for (int s : source_segment) segments = std::max(segments, s + 1);
  for (int s : target_segment) segments = std::max(segments, s + 1);
  valid_by_segment.assign(segments, {});
  for (std::size_t i = 0; i < source_valid.size(); ++i)
    if (source_valid[i]) valid_by_segment[segment_of_source(i)].push_back(std::int32_t(i));
  std::vector<std::uint8_t> used(segments, 0);
  for (std::size_t i = 0; i < target_active.size(); ++i)
    if (target_active[i]) used[segment_of_target(i)] = 1;
  for (int s = 0; s < segments; ++s) {
    if (!used[s] || !valid_by_segment[s].empty()) continue;
    if (segments == 1)
      throw ValueError("no usable source patches: the source mask leaves no room for a whole patch, or the "
                       "exemplar is too small for the patch (rotated patches need a margin of about 1.5 patch "
                       "radii more)");
    throw ValueError(concat("target segment ", s, " has no source patches with the same label"));
  }
}

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

struct Matcher {
  const PatchSpace& space;
  const SearchConstraints& cons;
  int sw, sh, margin;

  Matcher(const PatchSpace& s, const SearchConstraints& c)
      : space(s), cons(c), sw(s.source->width), sh(s.source->height), margin(s.source_margin()) {}

  // Starts loading the first rows of the source patch at (cx, cy), if valid.
  inline void prefetch(int cx, int cy) const {
    if (cx < margin || cy < margin || cx >= sw - margin || cy >= sh - margin) return;
    const int r = space.radius, bytes = (2 * r + 1) * space.source->stride * int(sizeof(float));
    for (int dy = -r; dy <= std::min(r, 1 - r); ++dy) {
      const char* row = reinterpret_cast<const char*>(space.source->pixel(cx - r, cy + dy));
      for (int off = 0; off < bytes; off += 64) __builtin_prefetch(row + off);
    }
  }

  // Tries source (cx, cy) for target (tx, ty); keeps it if it lowers the cost.
  inline void try_candidate(int cx, int cy, int tx, int ty, int segment, std::int32_t& bx, std::int32_t& by,
                            float& bd, float& bcost) const {
    if (cx < margin || cy < margin || cx >= sw - margin || cy >= sh - margin) return;
    if (cx == bx && cy == by) return;
    const std::size_t si = std::size_t(cy) * sw + cx;
    if (!cons.allowed(si, segment)) return;
    const float pen = cons.penalty(si);
    const float d = patch_distance(space, cx, cy, tx, ty, bcost - pen);
    if (d + pen < bcost) {
      bx = cx;
      by = cy;
      bd = d;
      bcost = d + pen;
    }
  }
};

}  // namespace

void random_nnf(const PatchSpace& space, const SearchConstraints& cons, Nnf& nnf, std::uint64_t seed,
                int threads) {
  const int tw = space.target->width, th = space.target->height;
  nnf = Nnf(tw, th);
  parallel_for(th, threads, [&](int ty) {
    for (int tx = 0; tx < tw; ++tx) {
      const std::size_t i = nnf.index(tx, ty);
      if (!cons.target_active[i]) continue;
      Rng rng(seed, i);
      const auto& pool = cons.valid_by_segment[cons.segment_of_target(i)];
      const std::int32_t s = pool[rng.below(int(pool.size()))];
      nnf.x[i] = s % space.source->width;
      nnf.y[i] = s / space.source->width;
      nnf.dist[i] = patch_distance(space, nnf.x[i], nnf.y[i], tx, ty, kInf);
    }
  });
}

void refresh_distances(const PatchSpace& space, const SearchConstraints& cons, Nnf& nnf, int threads) {
  parallel_for(nnf.height, threads, [&](int ty) {
    for (int tx = 0; tx < nnf.width; ++tx) {
      const std::size_t i = nnf.index(tx, ty);
      if (cons.target_active[i]) nnf.dist[i] = patch_distance(space, nnf.x[i], nnf.y[i], tx, ty, kInf);
    }
  });
}

void patchmatch(const PatchSpace& space, const SearchConstraints& cons, Nnf& nnf, const PatchMatchParams& params,
                std::uint64_t stream) {
  const Matcher m(space, cons);
  const int tw = nnf.width, th = nnf.height;
  const int bands = (th + params.band_rows - 1) / params.band_rows;
  const int max_radius = std::max(m.sw, m.sh);
  for (int iter = 0; iter < params.iterations; ++iter) {
    const Nnf snapshot = nnf;  // what other bands see of this band's neighbours
    const bool forward = iter % 2 == 0;
    const int step = forward ? 1 : -1;
    parallel_for(bands, params.threads, [&](int band) {
      const int y0 = band * params.band_rows, y1 = std::min(th, y0 + params.band_rows);
      Rng rng(params.seed, mix64(stream * 1000003ull + iter) ^ std::uint64_t(band));
      for (int row = 0; row < y1 - y0; ++row) {
        const int ty = forward ? y0 + row : y1 - 1 - row;
        for (int col = 0; col < tw; ++col) {
          const int tx = forward ? col : tw - 1 - col;
          const std::size_t i = nnf.index(tx, ty);
          if (!cons.target_active[i]) continue;
          const int segment = cons.segment_of_target(i);
          std::int32_t bx = nnf.x[i], by = nnf.y[i];
          float bd = nnf.dist[i];
          float bcost = bd + cons.penalty(std::size_t(by) * m.sw + bx);
          // Propagation from the neighbours already visited in this sweep.
          const int nbr[2][2] = {{-step, 0}, {0, -step}};
          for (const auto& d : nbr) {
            const int nx = tx + d[0], ny = ty + d[1];
            if (nx < 0 || ny < 0 || nx >= tw || ny >= th) continue;
            const std::size_t ni = nnf.index(nx, ny);
            if (!cons.target_active[ni]) continue;
            const bool inside = ny >= y0 && ny < y1;
            const Nnf& src = inside ? nnf : snapshot;
            int cx, cy;
            propagate_candidate(space, src.x[ni], src.y[ni], nx, ny, d[0], d[1], cx, cy);
            m.try_candidate(cx, cy, tx, ty, segment, bx, by, bd, bcost);
          }
          // Random search in shrinking windows around the match after
          // propagation (Barnes et al. 2009). The candidates are drawn first
          // and their source rows prefetched: each is a likely cache miss, and
          // waiting for them one by one dominated the search time.
          int cand[2 * 32], n = 0;
          for (int r = max_radius; r >= 1 && n < 64; r /= 2)
            for (int k = 0; k < params.random_tries_per_scale && n < 64; ++k, n += 2) {
              cand[n] = bx + rng.between(-r, r);
              cand[n + 1] = by + rng.between(-r, r);
              m.prefetch(cand[n], cand[n + 1]);
            }
          for (int k = 0; k < n; k += 2) m.try_candidate(cand[k], cand[k + 1], tx, ty, segment, bx, by, bd, bcost);
          nnf.x[i] = bx;
          nnf.y[i] = by;
          nnf.dist[i] = bd;
        }
      }
    });
  }
}

Nnf upsample_nnf(const Nnf& coarse, const PatchSpace& space, const SearchConstraints& cons, int fw, int fh) {
  Nnf fine(fw, fh);
  const int sw = space.source->width, sh = space.source->height, margin = space.source_margin();
  for (int ty = 0; ty < fh; ++ty) {
    for (int tx = 0; tx < fw; ++tx) {
      const std::size_t i = fine.index(tx, ty);
      if (!cons.target_active[i]) continue;
      const int px = std::min(tx / 2, coarse.width - 1), py = std::min(ty / 2, coarse.height - 1);
      const std::size_t pi = coarse.index(px, py);
      int cx = 2 * coarse.x[pi], cy = 2 * coarse.y[pi];
      const int ox = tx - 2 * px, oy = ty - 2 * py;
      if (space.rotated()) {
        float rx, ry;
        rotate_offset(space.rotation(std::clamp(cx, 0, sw - 1), std::clamp(cy, 0, sh - 1), tx, ty), float(ox),
                      float(oy), rx, ry);
        cx += int(std::lround(rx));
        cy += int(std::lround(ry));
      } else {
        cx += ox;
        cy += oy;
      }
      cx = std::clamp(cx, margin, sw - 1 - margin);
      cy = std::clamp(cy, margin, sh - 1 - margin);
      const int segment = cons.segment_of_target(i);
      if (!cons.allowed(std::size_t(cy) * sw + cx, segment)) {
        // Parent's match is masked out at this level: fall back to any valid
        // source of the segment, chosen deterministically from the position.
        const auto& pool = cons.valid_by_segment[segment];
        const std::int32_t s = pool[mix64(i) % pool.size()];
        cx = s % sw;
        cy = s / sw;
      }
      fine.x[i] = cx;
      fine.y[i] = cy;
    }
  }
  return fine;
}

}  // namespace tempera

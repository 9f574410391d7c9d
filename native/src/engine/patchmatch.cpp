#include "tempera/engine/patchmatch.hpp"

#include <algorithm>
#include <limits>

#include "tempera/engine/error.hpp"
#include "tempera/engine/parallel.hpp"
#include "tempera/engine/rng.hpp"

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

// The best match of one target pixel while it is being searched.
struct Best {
  std::int32_t x, y;
  float rx, ry, dist, cost;  // cost = dist + source cost + field terms
};

struct Matcher {
  const PatchSpace& space;
  const SearchConstraints& cons;
  const PatchMatchParams& params;
  const OffsetField* snapshot;
  int sw, sh, margin;

  Matcher(const PatchSpace& s, const SearchConstraints& c, const PatchMatchParams& p, const OffsetField* snap)
      : space(s), cons(c), params(p), snapshot(snap), sw(s.source->width), sh(s.source->height),
        margin(s.source_margin()) {}

  // Each field term's boxes for row ty: term k's box of target tx at
  // row_boxes[k * width + tx].
  void prepare_row(int ty, std::vector<PairCostBox>& row_boxes) const {
    const std::size_t width = std::size_t(snapshot->width);
    row_boxes.assign(params.field_terms.size() * width, PairCostBox{});
    for (std::size_t k = 0; k < params.field_terms.size(); ++k)
      params.field_terms[k]->prepare_row(*params.context, *snapshot, ty, row_boxes.data() + k * width);
  }

  // The field terms' cost, or infinity once it reaches `limit`.
  float field_cost(const std::vector<PairCostBox>& boxes, int tx, int ty, int sx, int sy, float limit = kInf) const {
    float sum = 0.0f;
    for (std::size_t k = 0; k < boxes.size(); ++k) {
      sum += params.field_terms[k]->pair_cost(*params.context, *snapshot, boxes[k], tx, ty, sx, sy, limit - sum);
      if (sum >= limit) return kInf;
    }
    return sum;
  }

  // Starts loading what try_candidate() reads first of source (cx, cy), if
  // in range: its validity and usage cost (a random candidate's first two
  // misses) and, without field terms, the first rows of its patch. With them
  // the field cost rejects most random candidates before their patch is
  // read, and loading rows for nothing made the coherent method 5% slower.
  // Always inlined: GCC took this function, which only prefetches, for one
  // without effects and deleted every call to it.
  [[gnu::always_inline]] inline void prefetch(int cx, int cy) const {
    if (cx < margin || cy < margin || cx >= sw - margin || cy >= sh - margin) return;
    const std::size_t si = std::size_t(cy) * sw + cx;
    __builtin_prefetch(cons.source_valid.data() + si);
    if (!cons.source_cost.empty()) __builtin_prefetch(cons.source_cost.data() + si);
    if (!params.field_terms.empty()) return;
    const int r = space.radius, bytes = (2 * r + 1) * space.source->bytes_per_pixel();
    for (int dy = -r; dy <= std::min(r, 1 - r); ++dy) {
      const char* row = space.source->pixel_bytes(cx - r, cy + dy);
      for (int off = 0; off < bytes; off += 64) __builtin_prefetch(row + off);
    }
  }

  // Whether a field term whose box leaves (cx, cy) out costs it b.cost or
  // more alone: a known value, read before the candidate's source data (its
  // validity and usage cost, two likely cache misses for a random candidate).
  // The full test below rejects such a candidate too: every cost is >= 0, and
  // its limit there is at most b.cost.
  bool rejected_outside_boxes(const std::vector<PairCostBox>& boxes, int tx, int ty, int cx, int cy,
                              float cost) const {
    for (std::size_t k = 0; k < boxes.size(); ++k)
      if (!boxes[k].contains(cx, cy) &&
          params.field_terms[k]->pair_cost(*params.context, *snapshot, boxes[k], tx, ty, cx, cy, cost) == kInf)
        return true;
    return false;
  }

  // Tries source (cx, cy) (remainder rx, ry) for target (tx, ty); keeps it if
  // it lowers the cost.
  inline void try_candidate(int cx, int cy, float rx, float ry, int tx, int ty, int segment,
                            const std::vector<PairCostBox>& boxes, Best& b) const {
    if (cx < margin || cy < margin || cx >= sw - margin || cy >= sh - margin) return;
    if (cx == b.x && cy == b.y) return;
    if (rejected_outside_boxes(boxes, tx, ty, cx, cy, b.cost)) return;
    const std::size_t si = std::size_t(cy) * sw + cx;
    if (!cons.allowed(si, segment)) return;
    float extra = cons.cost(si);
    if (extra >= b.cost) return;
    // The field terms stop once they alone reach what is left of b.cost.
    if (!boxes.empty()) extra += field_cost(boxes, tx, ty, cx, cy, b.cost - extra);
    if (extra >= b.cost) return;
    // patch_distance may stop once its partial sum reaches the cutoff, so a
    // result >= cutoff is not the full distance: reject it whatever the
    // rounding of d + extra, and the early exit decides as the full sum would.
    const float cutoff = b.cost - extra;
    const float d = patch_distance(space, cx, cy, tx, ty, cutoff);
    if (d < cutoff && d + extra < b.cost) b = Best{cx, cy, rx, ry, d, d + extra};
  }
};

}  // namespace

namespace {

// Target i's random source (random_field's draw).
std::int32_t random_source(const SearchConstraints& cons, std::size_t i, std::uint64_t seed) {
  Rng rng(seed, i);
  const auto& pool = cons.valid_by_segment[cons.segment_of_target(i)];
  return pool[rng.below(int(pool.size()))];
}

}  // namespace

void random_field(const PatchSpace& space, const SearchConstraints& cons, OffsetField& field, std::uint64_t seed,
                  int threads) {
  const int tw = space.target->width, th = space.target->height;
  field = OffsetField(tw, th);
  parallel_for(th, threads, [&](int ty) {
    for (int tx = 0; tx < tw; ++tx) {
      const std::size_t i = field.index(tx, ty);
      if (!cons.target_active[i]) continue;
      const std::int32_t s = random_source(cons, i, seed);
      field.x[i] = s % space.source->width;
      field.y[i] = s / space.source->width;
      field.dist[i] = patch_distance(space, field.x[i], field.y[i], tx, ty, kInf);
    }
  });
}

void restart_pixels(const PatchSpace& space, const SearchConstraints& cons, OffsetField& field,
                    const std::vector<std::uint8_t>& restart, std::uint64_t seed) {
  if (restart.size() != field.x.size())
    throw ValueError(concat("restart mask has ", restart.size(), " pixels, the field ", field.x.size()));
  for (std::size_t i = 0; i < restart.size(); ++i) {
    if (!restart[i] || !cons.target_active[i]) continue;
    const std::int32_t s = random_source(cons, i, seed);
    field.x[i] = s % space.source->width;
    field.y[i] = s / space.source->width;
    field.rx[i] = field.ry[i] = 0.0f;
    field.dist[i] = kInf;
  }
}

void refresh_distances(const PatchSpace& space, const SearchConstraints& cons, OffsetField& field, int threads) {
  parallel_for(field.height, threads, [&](int ty) {
    for (int tx = 0; tx < field.width; ++tx) {
      const std::size_t i = field.index(tx, ty);
      if (cons.target_active[i]) field.dist[i] = patch_distance(space, field.x[i], field.y[i], tx, ty, kInf);
    }
  });
}

void legalize_field(const PatchSpace& space, const SearchConstraints& cons, OffsetField& field) {
  const int sw = space.source->width, sh = space.source->height, margin = space.source_margin();
  for (std::size_t i = 0; i < field.x.size(); ++i) {
    if (!cons.target_active[i]) {
      field.x[i] = field.y[i] = 0;
      field.rx[i] = field.ry[i] = 0.0f;
      continue;
    }
    const int x = std::clamp<int>(field.x[i], margin, sw - 1 - margin);
    const int y = std::clamp<int>(field.y[i], margin, sh - 1 - margin);
    const int segment = cons.segment_of_target(i);
    if (x == field.x[i] && y == field.y[i] && cons.allowed(std::size_t(y) * sw + x, segment)) continue;
    // Masked out here (or another segment): any valid source of the segment,
    // chosen deterministically from the position.
    const auto& pool = cons.valid_by_segment[segment];
    const std::int32_t s = pool[mix64(i) % pool.size()];
    field.x[i] = s % sw;
    field.y[i] = s / sw;
    field.rx[i] = field.ry[i] = 0.0f;
  }
}

void patchmatch(const PatchSpace& space, const SearchConstraints& cons, OffsetField& field,
                const PatchMatchParams& params, std::uint64_t stream) {
  const int tw = field.width, th = field.height;
  const int bands = (th + params.band_rows - 1) / params.band_rows;
  const SourceLayout* layout = cons.layout;
  const bool video = layout && std::any_of(layout->next_frame.begin(), layout->next_frame.end(),
                                           [](int s) { return s >= 0; });
  const std::vector<std::uint8_t>& matched = cons.matched();
  for (int iter = params.first_iteration; iter < params.first_iteration + params.iterations; ++iter) {
    const bool forward = iter % 2 == 0;
    const int step = forward ? 1 : -1;
    // What a band sees of its neighbours in other bands: the field as it was
    // before the sweep. Terms that read the field read all of it; propagation
    // only the row before each band's first (row b of `edges` for band b), so
    // the common case copies a row a band, not the whole field every sweep.
    const OffsetField snapshot = params.field_terms.empty() ? OffsetField() : field;
    OffsetField edges(tw, bands);
    for (int band = 0; band < bands; ++band) {
      const int ey = forward ? band * params.band_rows - 1 : std::min(th, (band + 1) * params.band_rows);
      if (ey < 0 || ey >= th) continue;
      const std::size_t from = field.index(0, ey), to = edges.index(0, band);
      std::copy_n(field.x.begin() + from, tw, edges.x.begin() + to);
      std::copy_n(field.y.begin() + from, tw, edges.y.begin() + to);
      std::copy_n(field.rx.begin() + from, tw, edges.rx.begin() + to);
      std::copy_n(field.ry.begin() + from, tw, edges.ry.begin() + to);
    }
    const Matcher m(space, cons, params, &snapshot);
    const int whole = std::max(m.sw, m.sh);
    // The first sweep of a search reaches the whole exemplar; with a radius
    // the later ones stay near the matches it and propagation found.
    const int max_radius = params.search_radius > 0 && iter > 0 ? std::min(params.search_radius, whole) : whole;
    parallel_for(bands, params.threads, [&](int band) {
      const int y0 = band * params.band_rows, y1 = std::min(th, y0 + params.band_rows);
      Rng rng(params.seed, mix64(stream * 1000003ull + iter) ^ std::uint64_t(band));
      std::vector<PairCostBox> row_boxes, boxes(params.field_terms.size());
      for (int row = 0; row < y1 - y0; ++row) {
        const int ty = forward ? y0 + row : y1 - 1 - row;
        if (!params.field_terms.empty()) m.prepare_row(ty, row_boxes);
        for (int col = 0; col < tw; ++col) {
          const int tx = forward ? col : tw - 1 - col;
          const std::size_t i = field.index(tx, ty);
          if (!cons.target_active[i] || (params.searched && !(*params.searched)[i])) continue;
          const int segment = cons.segment_of_target(i);
          Best b{field.x[i], field.y[i], field.rx[i], field.ry[i], field.dist[i], 0.0f};
          b.cost = b.dist + cons.cost(std::size_t(b.y) * m.sw + b.x);
          if (!params.field_terms.empty()) {
            for (std::size_t k = 0; k < boxes.size(); ++k) boxes[k] = row_boxes[k * std::size_t(tw) + tx];
            b.cost += m.field_cost(boxes, tx, ty, b.x, b.y);
          }
          // Propagation from the neighbours already visited in this sweep.
          const int nbr[2][2] = {{-step, 0}, {0, -step}};
          for (const auto& d : nbr) {
            const int nx = tx + d[0], ny = ty + d[1];
            if (nx < 0 || ny < 0 || nx >= tw || ny >= th) continue;
            const std::size_t ni = field.index(nx, ny);
            if (!matched[ni]) continue;
            const bool inside = ny >= y0 && ny < y1;
            const OffsetField& src = inside ? field : edges;
            const std::size_t si = inside ? ni : edges.index(nx, band);
            int cx, cy;
            propagate_candidate(space, src.x[si], src.y[si], nx, ny, d[0], d[1], cx, cy);
            m.try_candidate(cx, cy, src.rx[si], src.ry[si], tx, ty, segment, boxes, b);
          }
          // Candidates the method proposes (Bénard's ribbons).
          if (params.candidates && !params.candidates->empty())
            for (std::uint32_t k = params.candidates->begin[i]; k < params.candidates->begin[i + 1]; ++k)
              m.try_candidate(params.candidates->x[k], params.candidates->y[k], 0.0f, 0.0f, tx, ty, segment, boxes,
                            b);
          // A video exemplar: the same place one frame later and earlier.
          if (video) {
            const int s = layout->source_at(b.y);
            for (int o : {layout->next_frame[s], layout->previous_frame[s]})
              if (o >= 0)
                m.try_candidate(b.x, b.y - layout->rects[s].y0 + layout->rects[o].y0, b.rx, b.ry, tx, ty, segment,
                                boxes, b);
          }
          // Random search in shrinking windows around the match after
          // propagation (Barnes et al. 2009). The candidates are drawn first
          // and their source rows prefetched: each is a likely cache miss, and
          // waiting for them one by one dominated the search time.
          int cand[2 * 32], n = 0;
          for (int r = max_radius; r >= 1 && n < 64; r /= 2)
            for (int k = 0; k < params.random_tries_per_scale && n < 64; ++k, n += 2) {
              cand[n] = b.x + rng.between(-r, r);
              cand[n + 1] = b.y + rng.between(-r, r);
              m.prefetch(cand[n], cand[n + 1]);
            }
          for (int k = 0; k < n; k += 2)
            m.try_candidate(cand[k], cand[k + 1], 0.0f, 0.0f, tx, ty, segment, boxes, b);
          field.x[i] = b.x;
          field.y[i] = b.y;
          field.rx[i] = b.rx;
          field.ry[i] = b.ry;
          field.dist[i] = b.dist;
        }
      }
    });
  }
}

}  // namespace tempera

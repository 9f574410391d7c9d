#include "tempera/methods/tcia/tcia_ribbons.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tempera/engine/solver.hpp"
#include "tempera/methods/tcia/tcia.hpp"

namespace tempera {

namespace {

constexpr float kBroken = std::numeric_limits<float>::quiet_NaN();

// Where the point at (x, y) of frame `from` is in frame `to`, followed
// frame by frame along V- (to < from) or V+ (to > from), each step with the
// velocity and χ of the nearest pixel (no blending across motion
// boundaries); false where χ = 0 or the point leaves the picture. Each pixel
// is followed on its own: carrying a neighbour's end plus the sub-pixel
// remainder, as the sweeps advect offsets, drifted 3 px over 23 frames of
// a turning surface (the remainder turns with the surface).
bool follow(const Shot& shot, int from, int to, float& x, float& y) {
  const bool back = to < from;
  for (int t = from; t != to; t += back ? -1 : 1) {
    const ShotFrame& f = shot.frames[std::size_t(t)];
    const ImageView& v = back ? f.velocity_backward : f.velocity_forward;
    const ImageView& visible = back ? f.occlusion_backward : f.occlusion_forward;
    const int nx = int(std::lround(x)), ny = int(std::lround(y));
    if (nx < 0 || ny < 0 || nx >= v.width || ny >= v.height || visible.at(nx, ny, 0) <= 0.5f) return false;
    const float sign = back ? -1.0f : 1.0f;
    x += sign * v.at(nx, ny, 0), y += sign * v.at(nx, ny, 1);
  }
  const int nx = int(std::lround(x)), ny = int(std::lround(y));
  return nx >= 0 && ny >= 0 && nx < shot.frames[0].velocity_backward.width &&
         ny < shot.frames[0].velocity_backward.height;
}

// The ends in key frame `key_frame` of every pixel of frame t.
Image ends(const Shot& shot, int t, int key_frame) {
  const ImageView& sized = shot.frames[0].velocity_backward;
  Image out(sized.width, sized.height, 2, kBroken);
  for (int y = 0; y < sized.height; ++y)
    for (int x = 0; x < sized.width; ++x) {
      float ex = float(x), ey = float(y);
      if (follow(shot, t, key_frame, ex, ey)) out.at(x, y, 0) = ex, out.at(x, y, 1) = ey;
    }
  return out;
}

}  // namespace

std::vector<FrameRibbons> trace_ribbons(const Shot& shot) {
  std::vector<FrameRibbons> out(shot.frames.size());
  std::size_t next = 0;  // the first key at or after t
  for (int t = 0; t < int(shot.frames.size()); ++t) {
    while (next < shot.keys.size() && shot.keys[next].frame < t) ++next;
    FrameRibbons& r = out[std::size_t(t)];
    if (next < shot.keys.size() && shot.keys[next].frame == t) continue;  // a key: its own pixels
    if (next > 0) r.previous_key = int(next) - 1, r.to_previous = ends(shot, t, shot.keys[next - 1].frame);
    if (next < shot.keys.size()) r.next_key = int(next), r.to_next = ends(shot, t, shot.keys[next].frame);
  }
  return out;
}

CandidateList ribbon_candidates(const FrameRibbons& ribbons, const Solver& solver, int level, int margin) {
  const int w = solver.target_width(level), h = solver.target_height(level);
  const SourceLayout& layout = solver.layout(level);
  CandidateList out;
  out.begin.assign(std::size_t(w) * h + 1, 0);
  for (int ty = 0; ty < h; ++ty)
    for (int tx = 0; tx < w; ++tx) {
      const std::size_t i = std::size_t(ty) * w + tx;
      out.begin[i + 1] = out.begin[i];
      for (const auto& [ends, key] : {std::pair{&ribbons.to_previous, ribbons.previous_key},
                                      std::pair{&ribbons.to_next, ribbons.next_key}}) {
        if (key < 0) continue;
        // The full-size pixel under the level pixel (a pick, as the sweeps' velocities).
        const int fx = std::min(ends->width() - 1, int((tx + 0.5) * ends->width() / w));
        const int fy = std::min(ends->height() - 1, int((ty + 0.5) * ends->height() / h));
        const float kx = ends->at(fx, fy, 0), ky = ends->at(fx, fy, 1);
        if (std::isnan(kx)) continue;
        // Padded key pixel -> this level's pixel of the key's exemplar.
        const SourceRect& rect = layout.rects[std::size_t(key + 1)];
        const float sx = float(rect.width) / float(ends->width() + 2 * margin);
        const float sy = float(rect.height) / float(ends->height() + 2 * margin);
        float ax, ay;
        solver.to_atlas(level, key + 1, (kx + margin + 0.5f) * sx - 0.5f, (ky + margin + 0.5f) * sy - 0.5f, ax, ay);
        out.x.push_back(std::int32_t(std::lround(ax)));
        out.y.push_back(std::int32_t(std::lround(ay)));
        ++out.begin[i + 1];
      }
    }
  return out;
}

}  // namespace tempera

#include "tempera/engine/offset_field.hpp"

#include <algorithm>
#include <limits>

#include "tempera/engine/error.hpp"

namespace tempera {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Source position for target (tx, ty) from a match at (px, py) of target
// (ox_t, oy_t) plus the target offset (dx, dy), rotated into source space.
void offset_position(const FieldGeometry& g, float px, float py, int tx, int ty, float dx, float dy, float& sx,
                     float& sy) {
  if (g.space && g.space->rotated()) {
    const int sw = g.space->source->width, sh = g.space->source->height;
    float ox, oy;
    rotate_offset(g.space->rotation(std::clamp(int(std::lround(px)), 0, sw - 1),
                                    std::clamp(int(std::lround(py)), 0, sh - 1), tx, ty),
                  dx, dy, ox, oy);
    dx = ox;
    dy = oy;
  }
  sx = px + dx;
  sy = py + dy;
}

int margin_of(const FieldGeometry& g) { return g.space ? g.space->source_margin() : 0; }

}  // namespace

OffsetField resample_field(const OffsetField& from, const SourceLayout& from_layout, const FieldGeometry& to,
                           int tw, int th, double scale) {
  if (from.width <= 0 || from.height <= 0) throw ValueError("cannot resample an empty offset field");
  OffsetField out(tw, th);
  std::fill(out.dist.begin(), out.dist.end(), kInf);
  // `scale` is the nominal size ratio of the levels (2 from one level of a
  // 0.5 pyramid to the next finer), for targets and sources alike, so that odd
  // sizes do not shift the mapping.
  const double kx = scale, ky = scale, sx_ratio = scale;
  const int margin = margin_of(to);
  for (int ty = 0; ty < th; ++ty) {
    // Parent pixel: t / k rounded down. For k = 2 this is t / 2 and the
    // offset below is t - 2 p, the classic NNF upsampling.
    const int py = std::min(int(ty / ky), from.height - 1);
    for (int tx = 0; tx < tw; ++tx) {
      const int px = std::min(int(tx / kx), from.width - 1);
      const std::size_t pi = from.index(px, py);
      const int s = from_layout.source_at(std::clamp(from.y[pi], 0, from_layout.height - 1));
      const float local_x = from.position_x(pi);
      const float local_y = from.position_y(pi) - float(from_layout.rects[s].y0);
      const float base_x = float(local_x * sx_ratio), base_y = float(local_y * sx_ratio);
      float sx, sy;
      offset_position(to, base_x, base_y + float(to.layout->rects[s].y0), tx, ty, float(tx - px * kx),
                      float(ty - py * ky), sx, sy);
      to.layout->clamp(s, margin, sx, sy);
      out.set_position(out.index(tx, ty), sx, sy);
    }
  }
  return out;
}

OffsetField advect_field(const OffsetField& prev, const ImageView& v, const FieldGeometry& at) {
  if (v.channels < 2 || v.width != prev.width || v.height != prev.height)
    throw ValueError(concat("velocity for advection must be ", prev.width, "x", prev.height,
                            " with 2 channels, got ", v.width, "x", v.height, "x", v.channels));
  OffsetField out(prev.width, prev.height);
  std::fill(out.dist.begin(), out.dist.end(), kInf);
  const int margin = margin_of(at);
  for (int ty = 0; ty < prev.height; ++ty)
    for (int tx = 0; tx < prev.width; ++tx) {
      const float qx = float(tx) - v.at(tx, ty, 0), qy = float(ty) - v.at(tx, ty, 1);  // p - V-(p)
      const int nx = std::clamp(int(std::lround(qx)), 0, prev.width - 1);
      const int ny = std::clamp(int(std::lround(qy)), 0, prev.height - 1);
      const std::size_t ni = prev.index(nx, ny);
      const int s = at.layout->source_at(std::clamp(prev.y[ni], 0, at.layout->height - 1));
      float sx, sy;
      offset_position(at, prev.position_x(ni), prev.position_y(ni), nx, ny, qx - float(nx), qy - float(ny), sx,
                      sy);
      at.layout->clamp(s, margin, sx, sy);
      out.set_position(out.index(tx, ty), sx, sy);
    }
  return out;
}

Image field_positions(const OffsetField& field) {
  Image out(field.width, field.height, 2);
  for (std::size_t i = 0; i < out.pixel_count(); ++i)
    out.data()[2 * i] = field.position_x(i), out.data()[2 * i + 1] = field.position_y(i);
  return out;
}

OffsetField field_from_positions(const ImageView& positions) {
  if (positions.channels != 2)
    throw ValueError(concat("a field's positions need 2 channels, got ", positions.channels));
  OffsetField field(positions.width, positions.height);
  std::fill(field.dist.begin(), field.dist.end(), kInf);
  for (int y = 0; y < positions.height; ++y)
    for (int x = 0; x < positions.width; ++x) {
      const float px = positions.at(x, y, 0), py = positions.at(x, y, 1);
      if (!std::isfinite(px) || !std::isfinite(py))
        throw ValueError(concat("a field's position at (", x, ", ", y, ") is not finite"));
      field.set_position(field.index(x, y), px, py);
    }
  return field;
}

}  // namespace tempera

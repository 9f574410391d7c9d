#pragma once
// Offset fields (nearest-neighbour fields, M in Bénard et al. 2013): for each
// target pixel, the centre of its source patch in the level's source atlas
// (source_set.hpp) with a sub-pixel remainder, and their patch distance.
// Patches are compared at the integer centre; the remainder is what makes slow
// motion survive advection and coarse-to-fine upsampling instead of rounding
// away (Bénard §3.3).
#include <cmath>
#include <cstdint>
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/engine/patch_distance.hpp"
#include "tempera/engine/source_set.hpp"

namespace tempera {

struct OffsetField {
  int width = 0;
  int height = 0;
  std::vector<std::int32_t> x, y;  // integer source centre (atlas pixels)
  std::vector<float> rx, ry;       // remainder in [-0.5, 0.5]: the source position is x + rx
  std::vector<float> dist;         // patch distance at (x, y)

  OffsetField() = default;
  OffsetField(int w, int h)
      : width(w), height(h), x(std::size_t(w) * h), y(std::size_t(w) * h), rx(std::size_t(w) * h),
        ry(std::size_t(w) * h), dist(std::size_t(w) * h) {}
  std::size_t index(int tx, int ty) const { return std::size_t(ty) * width + tx; }
  float position_x(std::size_t i) const { return float(x[i]) + rx[i]; }
  float position_y(std::size_t i) const { return float(y[i]) + ry[i]; }
  // Sets target i's source to the sub-pixel position (px, py).
  void set_position(std::size_t i, float px, float py) {
    x[i] = std::int32_t(std::lround(px));
    y[i] = std::int32_t(std::lround(py));
    rx[i] = px - float(x[i]);
    ry[i] = py - float(y[i]);
  }
};

// Geometry of one level that moving a field between levels or frames needs.
struct FieldGeometry {
  const SourceLayout* layout = nullptr;
  const PatchSpace* space = nullptr;  // rotation (source/target angles) and margins at this level
};

// The field of another level: each target pixel t takes its parent p (t
// scaled by the size ratio) and the parent's source position scaled by the
// level ratio, plus t's offset from the parent, rotated into source space.
// `scale` is the nominal level ratio (2 = to the next finer level of a 0.5
// pyramid, 0.5 = to the next coarser). Works both ways. Positions stay inside their
// exemplar. Distances are left at +inf (refresh them at the new level).
OffsetField resample_field(const OffsetField& from, const SourceLayout& from_layout, const FieldGeometry& to,
                           int to_width, int to_height, double scale);

// Bénard's advection along the backward velocity V- (target pixels, x right,
// y down): target p takes the nearest pixel p~ to p - V-(p) in `previous`
// and M(p) = M_prev(p~) + Rot_phi(p~) ((p - V-(p)) - p~), so the sub-pixel
// part of the motion is kept. Positions stay inside their exemplar.
// Distances are +inf.
OffsetField advect_field(const OffsetField& previous, const ImageView& velocity_backward, const FieldGeometry& at);

// A field's source positions (x + rx, y + ry) as a 2-channel float image,
// and back (distances +inf): what a warm start of the next frame needs,
// exactly, through an EXR file or numpy.
Image field_positions(const OffsetField& field);
OffsetField field_from_positions(const ImageView& positions);

}  // namespace tempera

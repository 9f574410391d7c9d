// Bénard et al. 2013, eq. 5: g_sc = min(|M(p + d) - C(p, d)|^2, r_max), summed
// over the patch window with its weights. C(p, d) is where the candidate's
// patch puts the neighbour p + d; neighbours whose own match agrees make the
// candidate cheaper, so the field prefers large coherent pieces.
#include <algorithm>

#include "tempera/engine/energy_term.hpp"
#include "tempera/engine/patchmatch.hpp"

namespace tempera {
namespace {

class SpatialCoherence final : public EnergyTerm {
 public:
  SpatialCoherence(float weight, float r_max) : weight_(weight), r_max2_(r_max * r_max) {}
  const char* name() const override { return "spatial_coherence"; }
  bool reads_field() const override { return true; }
  float pair_cost(const LevelContext& c, const OffsetField& field, int tx, int ty, int sx, int sy) const override {
    const PatchSpace& s = *c.space;
    const int r = s.radius, side = 2 * r + 1;
    const float phi = s.rotated() ? s.rotation(sx, sy, tx, ty) : 0.0f;
    float sum = 0.0f;
    for (int dy = -r; dy <= r; ++dy) {
      const int ny = ty + dy;
      if (ny < 0 || ny >= field.height) continue;
      for (int dx = -r; dx <= r; ++dx) {
        const int nx = tx + dx;
        if (nx < 0 || nx >= field.width || (dx == 0 && dy == 0)) continue;
        const std::size_t ni = field.index(nx, ny);
        if (!c.constraints->matched()[ni]) continue;
        float ox = float(dx), oy = float(dy);
        if (phi != 0.0f) rotate_offset(phi, float(dx), float(dy), ox, oy);
        const float ex = float(field.x[ni]) - (float(sx) + ox), ey = float(field.y[ni]) - (float(sy) + oy);
        const float w = s.window ? s.window[(dy + r) * side + dx + r] : 1.0f;
        sum += w * std::min(ex * ex + ey * ey, r_max2_);
      }
    }
    return weight_ * sum;
  }

 private:
  float weight_, r_max2_;
};

}  // namespace

std::shared_ptr<const EnergyTerm> make_spatial_coherence(float weight, float r_max) {
  return std::make_shared<SpatialCoherence>(weight, r_max);
}

}  // namespace tempera

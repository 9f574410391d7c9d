// Fluidymation's uniformity term (Platkevič et al. 2021, §3, Omega): usage
// counted over patch footprints rather than centres. Each exemplar pixel
// counts how many output patches cover it; a patch costs more the more its
// own footprint is covered already, relative to fair use. With a temporal
// radius r the footprint is the paper's n x n x (2r + 1) cuboid: in a video
// exemplar, coverage is averaged over the r frames either side.
#include <algorithm>

#include "tempera/engine/patch_usage.hpp"

namespace tempera {
namespace {

// Sum over the (2r+1)^2 window around each pixel of a width x height grid.
std::vector<float> box_sum(const std::vector<float>& in, int width, int height, int r) {
  std::vector<float> tmp(in.size(), 0.0f), out(in.size(), 0.0f);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float s = 0;
      for (int i = std::max(0, x - r); i <= std::min(width - 1, x + r); ++i) s += in[std::size_t(y) * width + i];
      tmp[std::size_t(y) * width + x] = s;
    }
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float s = 0;
      for (int j = std::max(0, y - r); j <= std::min(height - 1, y + r); ++j) s += tmp[std::size_t(j) * width + x];
      out[std::size_t(y) * width + x] = s;
    }
  return out;
}

// Coverage of each atlas pixel averaged over the same pixel of the frames
// up to r steps before and after it in its video (the atlas links frames).
std::vector<float> temporal_mean(const std::vector<float>& in, const SourceLayout& lay, int width, int r) {
  std::vector<float> out(in.size(), 0.0f);
  for (std::size_t e = 0; e < lay.rects.size(); ++e) {
    std::vector<int> frames = {int(e)};
    for (int k = 0, f = int(e); k < r && (f = lay.next_frame[std::size_t(f)]) >= 0; ++k) frames.push_back(f);
    for (int k = 0, f = int(e); k < r && (f = lay.previous_frame[std::size_t(f)]) >= 0; ++k) frames.push_back(f);
    const SourceRect& rect = lay.rects[e];
    for (int y = 0; y < rect.height; ++y)
      for (int x = 0; x < rect.width; ++x) {
        float sum = 0;
        for (int f : frames) sum += in[std::size_t(lay.rects[std::size_t(f)].y0 + y) * width + x];
        out[std::size_t(rect.y0 + y) * width + x] = sum / float(frames.size());
      }
  }
  return out;
}

class FootprintUsage final : public EnergyTerm {
 public:
  FootprintUsage(float weight, int temporal_radius) : weight_(weight), temporal_radius_(temporal_radius) {}
  const char* name() const override { return "footprint"; }
  // Held through a whole search, the costs would send every target of a
  // covered region to the same next-best footprint at once.
  bool refresh_each_iteration() const override { return true; }
  void add_source_costs(const LevelContext& c, const OffsetField& field, std::vector<float>& cost,
                        TermState&) const override {
    const int sw = c.space->source->width, sh = c.space->source->height, r = c.space->radius;
    // Coverage of each exemplar pixel by used footprints, then the coverage
    // a candidate centre's own footprint would land on.
    std::vector<float> covered = box_sum(usage_counts(field, *c.constraints, sw), sw, sh, r);
    if (temporal_radius_ > 0 && c.layout) covered = temporal_mean(covered, *c.layout, sw, temporal_radius_);
    const std::vector<float> crowd = box_sum(covered, sw, sh, r);
    const UsageScale scale = usage_scale(field, *c.constraints);
    if (!scale.valid) return;
    const float area = float((2 * r + 1) * (2 * r + 1));
    // Fair coverage of a pixel is omega * area; a footprint sums area pixels.
    const float fair = scale.fair * area * area;
    for (std::size_t p = 0; p < cost.size(); ++p) cost[p] += weight_ * scale.typical * crowd[p] / fair;
  }

 private:
  float weight_;
  int temporal_radius_;
};

}  // namespace

std::shared_ptr<const EnergyTerm> make_footprint_usage(float weight, int temporal_radius) {
  return std::make_shared<FootprintUsage>(weight, temporal_radius);
}

}  // namespace tempera

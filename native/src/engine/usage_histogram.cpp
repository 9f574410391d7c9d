// Bénard et al. 2013, eq. 8: g_h = h_s max(0, H(M(p)) - h_tau), with H the
// usage count of each exemplar pixel blurred by a small Gaussian. The paper
// gives no values; here H is divided by the fair use omega (targets per valid
// source patch) and the cost by the median patch distance d~, so h_s and
// h_tau mean the same at every level and frame size (docs/engine.md).
#include <algorithm>
#include <cmath>

#include "tempera/engine/patch_usage.hpp"

namespace tempera {
namespace {

// Separable Gaussian blur of a width x height grid, zero outside.
std::vector<float> gaussian_blur(const std::vector<float>& in, int width, int height, float sigma) {
  if (sigma <= 0) return in;
  const int r = std::max(1, std::min(int(std::ceil(3 * sigma)), std::max(width, height)));
  std::vector<float> k(2 * r + 1);
  float sum = 0;
  for (int i = -r; i <= r; ++i) sum += k[i + r] = std::exp(-0.5f * float(i * i) / (sigma * sigma));
  for (auto& v : k) v /= sum;
  std::vector<float> tmp(in.size(), 0.0f), out(in.size(), 0.0f);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float acc = 0;
      for (int i = std::max(-r, -x); i <= std::min(r, width - 1 - x); ++i) acc += k[i + r] * in[std::size_t(y) * width + x + i];
      tmp[std::size_t(y) * width + x] = acc;
    }
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float acc = 0;
      for (int i = std::max(-r, -y); i <= std::min(r, height - 1 - y); ++i)
        acc += k[i + r] * tmp[std::size_t(y + i) * width + x];
      out[std::size_t(y) * width + x] = acc;
    }
  return out;
}

class UsageHistogram final : public EnergyTerm {
 public:
  UsageHistogram(float weight, float threshold, float sigma) : weight_(weight), threshold_(threshold), sigma_(sigma) {}
  const char* name() const override { return "histogram"; }
  // Eq. 8 is evaluated against the current M_t (§3.3: at every iteration).
  bool refresh_each_iteration() const override { return true; }
  void add_source_costs(const LevelContext& c, const OffsetField& field, std::vector<float>& cost,
                        TermState& state) const override {
    const int sw = c.space->source->width, sh = c.space->source->height;
    const std::vector<float> now = gaussian_blur(usage_counts(field, *c.constraints, sw), sw, sh, sigma_);
    // The running mean of the histogram over this level's iterations: every
    // target sees the same costs during a sweep, so a plain histogram makes
    // the crowd of a hotspot move together to the same free patch and
    // oscillate; the mean remembers where the crowd has been.
    std::vector<float>& h = state.values;
    if (h.size() != now.size()) h.assign(now.size(), 0.0f);
    const float keep = float(state.updates) / float(state.updates + 1);
    for (std::size_t p = 0; p < h.size(); ++p) h[p] = keep * h[p] + (1 - keep) * now[p];
    ++state.updates;
    const UsageScale scale = usage_scale(field, *c.constraints);
    if (!scale.valid) return;
    const float typical = scale.typical, fair = scale.fair;
    // Saturated one threshold above it: an overused patch costs at most h_s
    // typical patch distances more, so targets leave it for nearby patches of
    // similar fit instead of stampeding, all at once, to wherever no patch is
    // used yet (the term is evaluated against the field before the sweep).
    const float span = std::max(threshold_, 1.0f);
    for (std::size_t p = 0; p < cost.size(); ++p)
      cost[p] += weight_ * typical * std::clamp((h[p] / fair - threshold_) / span, 0.0f, 1.0f);
  }

 private:
  float weight_, threshold_, sigma_;
};

}  // namespace

std::shared_ptr<const EnergyTerm> make_usage_histogram(float weight, float threshold, float sigma) {
  return std::make_shared<UsageHistogram>(weight, threshold, sigma);
}

}  // namespace tempera

// The occurrence penalty (Kaspar et al. 2015): a source patch costs more the
// more targets already use it.
#include <algorithm>

#include "tempera/engine/patch_usage.hpp"

namespace tempera {

UsageScale usage_scale(const OffsetField& field, const SearchConstraints& cons) {
  std::vector<float> dists;
  for (std::size_t q = 0; q < cons.target_active.size(); ++q)
    if (cons.target_active[q]) dists.push_back(field.dist[q]);
  std::size_t valid = 0;
  for (auto v : cons.source_valid) valid += v;
  UsageScale s;
  if (dists.empty() || valid == 0) return s;
  std::nth_element(dists.begin(), dists.begin() + dists.size() / 2, dists.end());
  s.typical = std::max(dists[dists.size() / 2], 1e-6f);
  s.fair = float(dists.size()) / float(valid);  // omega: uses per source if uniform
  s.valid = true;
  return s;
}

std::vector<float> occurrence_penalty(const OffsetField& field, const SearchConstraints& cons, int source_width,
                                      float weight) {
  std::vector<float> uses = usage_counts(field, cons, source_width);
  const UsageScale s = usage_scale(field, cons);
  if (!s.valid) return uses;
  for (auto& u : uses) u = weight * s.typical * u / s.fair;
  return uses;
}

std::vector<float> usage_counts(const OffsetField& field, const SearchConstraints& cons, int source_width) {
  std::vector<float> uses(cons.source_valid.size(), 0.0f);
  for (std::size_t q = 0; q < cons.target_active.size(); ++q)
    if (cons.target_active[q]) uses[std::size_t(field.y[q]) * source_width + field.x[q]] += 1.0f;
  return uses;
}

double source_coverage(const OffsetField& nnf, const SearchConstraints& cons, int source_width) {
  std::vector<std::uint8_t> used(cons.source_valid.size(), 0);
  for (std::size_t q = 0; q < cons.target_active.size(); ++q)
    if (cons.target_active[q]) used[std::size_t(nnf.y[q]) * source_width + nnf.x[q]] = 1;
  std::size_t valid = 0, hit = 0;
  for (std::size_t p = 0; p < used.size(); ++p) valid += cons.source_valid[p], hit += used[p] && cons.source_valid[p];
  return valid ? double(hit) / double(valid) : 0.0;
}

namespace {

class OccurrencePenalty final : public EnergyTerm {
 public:
  explicit OccurrencePenalty(float weight) : weight_(weight) {}
  const char* name() const override { return "penalty"; }
  void add_source_costs(const LevelContext& c, const OffsetField& field, std::vector<float>& cost,
                        TermState&) const override {
    const std::vector<float> pen = occurrence_penalty(field, *c.constraints, c.space->source->width, weight_);
    for (std::size_t i = 0; i < cost.size(); ++i) cost[i] += pen[i];
  }

 private:
  float weight_;
};

}  // namespace

std::shared_ptr<const EnergyTerm> make_occurrence_penalty(float weight) {
  return std::make_shared<OccurrencePenalty>(weight);
}

}  // namespace tempera

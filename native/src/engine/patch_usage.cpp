// The patch-usage term each `usage` option value stands for.
#include "tempera/engine/patch_usage.hpp"

namespace tempera {

std::shared_ptr<const EnergyTerm> make_usage_term(const SynthesisOptions& o) {
  switch (o.usage) {
    case PatchUsage::None: return nullptr;
    case PatchUsage::Penalty: return make_occurrence_penalty(o.penalty_weight);
    case PatchUsage::Uniform: return make_uniform_usage();
    case PatchUsage::Budget: return make_error_budget(o.budget_coverage, o.budget_max_rounds);
    case PatchUsage::Histogram: return make_usage_histogram(o.histogram_weight, o.histogram_threshold, o.histogram_sigma);
    case PatchUsage::Footprint: return make_footprint_usage(o.penalty_weight);
  }
  return nullptr;
}

}  // namespace tempera

#include "tempera/engine/guide_stack.hpp"

#include <cmath>

#include "tempera/engine/error.hpp"

namespace tempera {

void GuideStack::add(std::string name, ImageView source, ImageView target, float weight) {
  const std::string src_what = concat("guide '", name, "' source");
  const std::string tgt_what = concat("guide '", name, "' target");
  require_nonempty(source, src_what);
  require_nonempty(target, tgt_what);
  if (source.channels != target.channels)
    throw ValueError(concat("guide '", name, "' has ", source.channels, " source channels but ",
                            target.channels, " target channels"));
  if (!std::isfinite(weight) || weight < 0.0f)
    throw ValueError(concat("guide '", name, "' weight must be finite and >= 0, got ", weight));
  if (!layers_.empty()) {
    require_same_size(source, src_what, layers_.front().source,
                      concat("guide '", layers_.front().name, "' source"));
    require_same_size(target, tgt_what, layers_.front().target,
                      concat("guide '", layers_.front().name, "' target"));
  }
  require_finite(source, src_what);
  require_finite(target, tgt_what);
  layers_.push_back(GuideLayer{std::move(name), source, target, weight});
}

int GuideStack::total_channels() const {
  int total = 0;
  for (const auto& layer : layers_) total += layer.source.channels;
  return total;
}

}  // namespace tempera

#include "tempera/methods/fluidymation/motion_extent.hpp"

#include <cmath>

#include "tempera/engine/error.hpp"

namespace tempera {
namespace {

// |acc| per frame, accumulating in the order of `order` (frame indices):
// acc(order[k]) = acc(order[k-1]) + flows[from(k)], zeroed outside the mask.
std::vector<Image> accumulate(const std::function<Image(std::size_t)>& flow_of, const std::vector<ImageView>& masks,
                              bool forward) {
  const std::size_t n = masks.size();
  const std::size_t px = masks[0].pixel_count();
  std::vector<Image> out(n);
  std::vector<float> acc(2 * px, 0.0f);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = forward ? k : n - 1 - k;
    if (k > 0) {
      const std::size_t from = forward ? i - 1 : i;  // acc+ adds the flow that led here, acc- the one leaving
      const Image f = flow_of(from);
      if (f.channels() != 2 || f.width() != masks[0].width || f.height() != masks[0].height)
        throw ValueError(concat("flow ", from, " must be ", masks[0].width, "x", masks[0].height, " with 2 channels"));
      for (std::size_t p = 0; p < 2 * px; ++p) acc[p] += f.data()[p];
    }
    out[i] = Image(masks[i].width, masks[i].height, 1);
    for (std::size_t p = 0; p < px; ++p) {
      if (masks[i].data[p] <= 0.5f) acc[2 * p] = acc[2 * p + 1] = 0.0f;
      out[i].data()[p] = std::hypot(acc[2 * p], acc[2 * p + 1]);
    }
  }
  return out;
}

void check_masks(const std::vector<ImageView>& masks) {
  if (masks.empty()) throw ValueError("motion extent needs at least one mask");
  for (std::size_t i = 0; i < masks.size(); ++i) {
    if (masks[i].channels != 1) throw ValueError(concat("mask ", i, " must have 1 channel, got ", masks[i].channels));
    require_same_size(masks[i], concat("mask ", i), masks[0], "mask 0");
  }
}

}  // namespace

MotionExtent motion_extent(const std::vector<ImageView>& flows, const std::vector<ImageView>& masks) {
  if (flows.empty() || flows.size() != masks.size())
    throw ValueError(concat("motion extent needs one flow per mask, got ", flows.size(), " flows and ", masks.size(),
                            " masks"));
  check_masks(masks);
  for (std::size_t i = 0; i < flows.size(); ++i) {
    if (flows[i].channels != 2) throw ValueError(concat("flow ", i, " must have 2 channels, got ", flows[i].channels));
    require_same_size(flows[i], concat("flow ", i), masks[0], "mask 0");
    require_finite(flows[i], concat("flow ", i));
  }
  return motion_extent([&](std::size_t i) { return Image::copy_of(flows[i]); }, masks);
}

MotionExtent motion_extent(const std::function<Image(std::size_t)>& flow_of, const std::vector<ImageView>& masks) {
  check_masks(masks);
  return {accumulate(flow_of, masks, true), accumulate(flow_of, masks, false)};
}

}  // namespace tempera

#pragma once
// Motion extent (Platkevič et al. 2021, §3.3): how far the material at each
// pixel has moved since it appeared (ext+) and will move until it goes
// (ext-), the guides that pick exemplar frames with a matching amount of
// motion and that SHIFTNNF reads to advance a pixel's exemplar frame.
//   acc+(0) = 0, acc+(i) = acc+(i-1) + flow(i-1);  acc-(l-1) = 0, acc-(i) = acc-(i+1) + flow(i);
// each zeroed where the pixel is outside mask i (the accumulation restarts
// where material reappears); ext = |acc|. Per pixel, not along paths, as in
// the paper.
#include <functional>
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

struct MotionExtent {
  std::vector<Image> forward, backward;  // ext+ and ext- per frame, 1 channel, pixels
};

// flows: 2 channels per frame (pixels/frame, forward convention), masks: 1
// channel per frame (> 0.5 = inside), same count and size.
MotionExtent motion_extent(const std::vector<ImageView>& flows, const std::vector<ImageView>& masks);
// The same, frame i's flow made when it is read (twice: once each way), so
// that a shot's flows need not be held at once.
MotionExtent motion_extent(const std::function<Image(std::size_t)>& flow_of, const std::vector<ImageView>& masks);

}  // namespace tempera

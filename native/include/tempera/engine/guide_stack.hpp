#pragma once
// A guide stack: the named, weighted pairs of guide images (source A_g for the
// exemplar, target B_g for the frame to synthesize) that every solver takes.
// Methods add their own layers here (light-path buffers, temporal guides,
// distance transforms, ...) instead of forking the engine.
#include <string>
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

struct GuideLayer {
  std::string name;
  ImageView source;  // exemplar side (A_g)
  ImageView target;  // synthesized side (B_g)
  float weight = 1.0f;
};

class GuideStack {
 public:
  // Adds a layer; throws ValueError if it does not fit the layers already there.
  void add(std::string name, ImageView source, ImageView target, float weight = 1.0f);

  const std::vector<GuideLayer>& layers() const { return layers_; }
  bool empty() const { return layers_.empty(); }
  int total_channels() const;
  int source_width() const { return layers_.empty() ? 0 : layers_.front().source.width; }
  int source_height() const { return layers_.empty() ? 0 : layers_.front().source.height; }
  int target_width() const { return layers_.empty() ? 0 : layers_.front().target.width; }
  int target_height() const { return layers_.empty() ? 0 : layers_.front().target.height; }

 private:
  std::vector<GuideLayer> layers_;
};

}  // namespace tempera

#include "tempera/engine/source_set.hpp"

#include <algorithm>
#include <cstring>

#include "tempera/engine/error.hpp"

namespace tempera {

SourceLayout SourceLayout::stack(const std::vector<std::pair<int, int>>& sizes, const std::vector<int>& sequence,
                                 const std::vector<int>& time) {
  SourceLayout layout;
  for (const auto& [w, h] : sizes) {
    layout.rects.push_back({layout.height, w, h});
    layout.width = std::max(layout.width, w);
    layout.height += h;
    layout.row_source.insert(layout.row_source.end(), std::size_t(h), int(layout.rects.size()) - 1);
  }
  const int n = int(sizes.size());
  layout.next_frame.assign(n, -1);
  layout.previous_frame.assign(n, -1);
  for (int s = 0; s < n; ++s) {
    if (sequence[s] < 0) continue;
    for (int o = 0; o < n; ++o) {
      if (o == s || sequence[o] != sequence[s] || sizes[o] != sizes[s]) continue;
      if (time[o] == time[s] + 1) layout.next_frame[s] = o;
      if (time[o] == time[s] - 1) layout.previous_frame[s] = o;
    }
  }
  return layout;
}

void SourceLayout::clamp(int s, int margin, float& x, float& y) const {
  const SourceRect& r = rects[std::size_t(s)];
  x = std::clamp(x, float(margin), float(std::max(margin, r.width - 1 - margin)));
  y = std::clamp(y, float(r.y0 + margin), float(r.y0 + std::max(margin, r.height - 1 - margin)));
}

Image stack_atlas(std::vector<Image>&& images, const SourceLayout& layout) {
  if (images.size() == 1) return std::move(images.front());  // the common case: no copy
  const int c = images.front().channels();
  Image atlas(layout.width, layout.height, c);
  for (std::size_t s = 0; s < images.size(); ++s) {
    const Image& img = images[s];
    if (img.channels() != c) throw ValueError("internal: atlas parts differ in channels");
    for (int y = 0; y < img.height(); ++y)
      std::memcpy(atlas.pixel(0, layout.rects[s].y0 + y), img.pixel(0, y), sizeof(float) * img.width() * c);
  }
  return atlas;
}

}  // namespace tempera

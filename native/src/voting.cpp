#include "tempera/voting.hpp"

#include <algorithm>
#include <vector>

#include "tempera/parallel.hpp"

namespace tempera {

Image vote(const ImageView& style, const PatchSpace& space, const SearchConstraints& cons, const Nnf& nnf,
           const ImageView& previous, int threads) {
  const int tw = nnf.width, th = nnf.height, c = style.channels, r = space.radius;
  Image out(tw, th, c);
  if (!previous.empty()) std::copy_n(previous.data, previous.size(), out.data());
  parallel_for(th, threads, [&](int ty) {
    std::vector<float> sum(c), sample(c);
    for (int tx = 0; tx < tw; ++tx) {
      const std::size_t i = nnf.index(tx, ty);
      if (!cons.target_active[i]) continue;
      std::fill(sum.begin(), sum.end(), 0.0f);
      int count = 0;
      // Gather from every patch (centered at q') that covers q; q - q' is the
      // offset of q inside that patch.
      for (int dy = -r; dy <= r; ++dy) {
        const int qy = ty - dy;
        if (qy < 0 || qy >= th) continue;
        for (int dx = -r; dx <= r; ++dx) {
          const int qx = tx - dx;
          if (qx < 0 || qx >= tw) continue;
          const std::size_t qi = nnf.index(qx, qy);
          if (!cons.target_active[qi]) continue;
          const int px = nnf.x[qi], py = nnf.y[qi];
          if (space.rotated()) {
            float ox, oy;
            rotate_offset(space.rotation(px, py, qx, qy), float(dx), float(dy), ox, oy);
            sample_bilinear(style.data, style.width, style.height, c, c, px + ox, py + oy, sample.data());
            for (int k = 0; k < c; ++k) sum[k] += sample[k];
          } else {
            const float* s = style.pixel(px + dx, py + dy);
            for (int k = 0; k < c; ++k) sum[k] += s[k];
          }
          ++count;
        }
      }
      float* o = out.pixel(tx, ty);
      for (int k = 0; k < c; ++k) o[k] = sum[k] / float(count);
    }
  });
  return out;
}

}  // namespace tempera

#include "tempera/engine/converged_pixels.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "tempera/engine/error.hpp"
#include "tempera/engine/rng.hpp"

namespace tempera {
namespace {

std::uint32_t bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

// Pixels within `radius` (Chebyshev) of a set pixel: a separable box dilation.
std::vector<std::uint8_t> dilate(const std::vector<std::uint8_t>& set, int w, int h, int radius) {
  std::vector<std::uint8_t> rows(set.size(), 0), out(set.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (set[std::size_t(y) * w + x])
        for (int k = std::max(0, x - radius); k <= std::min(w - 1, x + radius); ++k) rows[std::size_t(y) * w + k] = 1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (rows[std::size_t(y) * w + x])
        for (int k = std::max(0, y - radius); k <= std::min(h - 1, y + radius); ++k) out[std::size_t(k) * w + x] = 1;
  return out;
}

}  // namespace

std::uint32_t match_fingerprint(const OffsetField& field, std::size_t i) {
  const std::uint64_t position = (std::uint64_t(std::uint32_t(field.x[i])) << 32) | std::uint32_t(field.y[i]);
  const std::uint64_t remainder = (std::uint64_t(bits(field.rx[i])) << 32) | bits(field.ry[i]);
  return std::uint32_t(mix64(position ^ mix64(remainder)));
}

std::vector<std::uint32_t> match_fingerprints(const OffsetField& field) {
  std::vector<std::uint32_t> out;
  match_fingerprints(field, out);
  return out;
}

void match_fingerprints(const OffsetField& field, std::vector<std::uint32_t>& out) {
  out.resize(field.x.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = match_fingerprint(field, i);
}

std::vector<std::uint8_t> changed_pixels(const ImageView& before, const ImageView& after) {
  require_same_size(after, "new image", before, "old image");
  std::vector<std::uint8_t> out(after.pixel_count(), 0);
  const int c = after.channels;
  for (std::size_t i = 0; i < out.size(); ++i)
    for (int k = 0; k < c && !out[i]; ++k)
      out[i] = !(std::abs(after.data[i * c + k] - before.data[i * c + k]) < kConvergedChange);
  return out;
}

void mark_moved(const OffsetField& field, const std::vector<std::uint32_t>& before, std::vector<std::uint8_t>& moved) {
  moved.resize(before.size(), 0);
  for (std::size_t i = 0; i < before.size(); ++i) moved[i] |= match_fingerprint(field, i) != before[i];
}

std::vector<std::uint8_t> pixels_to_search(int w, int h, const std::vector<std::uint8_t>& moved,
                                           const std::vector<std::uint8_t>& image_changed, int radius,
                                           const std::vector<std::uint8_t>& active) {
  std::vector<std::uint8_t> out = dilate(image_changed, w, h, radius);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      const bool nbr_moved = moved[i] || (x > 0 && moved[i - 1]) || (x + 1 < w && moved[i + 1]) ||
                             (y > 0 && moved[i - w]) || (y + 1 < h && moved[i + w]);
      out[i] = active[i] && (out[i] || nbr_moved);
    }
  return out;
}

}  // namespace tempera

#include "tempera/engine/image.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "tempera/engine/error.hpp"

namespace tempera {

Image::Image(int width, int height, int channels, float fill)
    : width_(width), height_(height), channels_(channels) {
  if (width <= 0 || height <= 0 || channels <= 0)
    throw ValueError(concat("image size must be positive, got ", width, "x", height, "x", channels));
  data_.assign(std::size_t(width) * std::size_t(height) * std::size_t(channels), fill);
}

Image Image::copy_of(const ImageView& view) {
  require_nonempty(view, "image");
  Image out(view.width, view.height, view.channels);
  std::memcpy(out.data(), view.data, view.size() * sizeof(float));
  return out;
}

void require_nonempty(const ImageView& image, std::string_view what) {
  if (image.empty())
    throw ValueError(concat(what, " is empty (", image.width, "x", image.height, "x",
                            image.channels, ")"));
}

void require_finite(const ImageView& image, std::string_view what) {
  const std::size_t n = image.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(image.data[i])) {
      const std::size_t pixel = i / std::size_t(image.channels);
      throw ValueError(concat(what, " contains a non-finite value (", image.data[i], ") at x=",
                              pixel % std::size_t(image.width), " y=", pixel / std::size_t(image.width),
                              " channel ", i % std::size_t(image.channels)));
    }
  }
}

void require_same_size(const ImageView& a, std::string_view a_what, const ImageView& b,
                       std::string_view b_what) {
  if (a.width != b.width || a.height != b.height)
    throw ValueError(concat(a_what, " is ", a.width, "x", a.height, " but ", b_what, " is ",
                            b.width, "x", b.height, "; they must have the same size"));
}

Image extract_channels(const ImageView& image, int first, int count) {
  if (first < 0 || count <= 0 || first + count > image.channels)
    throw ValueError(concat("channels [", first, ", ", first + count, ") out of range for an image with ",
                            image.channels, " channels"));
  Image out(image.width, image.height, count);
  const std::size_t n = image.pixel_count();
  for (std::size_t i = 0; i < n; ++i)
    std::copy_n(image.data + i * image.channels + first, count, out.data() + i * count);
  return out;
}

}  // namespace tempera

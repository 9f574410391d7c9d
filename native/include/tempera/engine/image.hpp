#pragma once
// Float images stored H x W x C, channels interleaved per pixel (the layout
// numpy gives for an (H, W, C) C-contiguous array, and the one patch
// distances read fastest).
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace tempera {

// A non-owning, read-only look at pixels that live elsewhere (a numpy array,
// an Image). Solvers take views so that inputs are never copied.
struct ImageView {
  const float* data = nullptr;
  int width = 0;
  int height = 0;
  int channels = 0;

  bool empty() const { return data == nullptr || width <= 0 || height <= 0 || channels <= 0; }
  std::size_t pixel_count() const { return std::size_t(width) * std::size_t(height); }
  std::size_t size() const { return pixel_count() * std::size_t(channels); }
  const float* pixel(int x, int y) const {
    return data + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * std::size_t(channels);
  }
  float at(int x, int y, int c) const { return pixel(x, y)[c]; }
};

class Image {
 public:
  Image() = default;
  Image(int width, int height, int channels, float fill = 0.0f);
  static Image copy_of(const ImageView& view);

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  bool empty() const { return data_.empty(); }
  std::size_t pixel_count() const { return std::size_t(width_) * std::size_t(height_); }

  float* data() { return data_.data(); }
  const float* data() const { return data_.data(); }
  float* pixel(int x, int y) {
    return data_.data() + (std::size_t(y) * std::size_t(width_) + std::size_t(x)) * std::size_t(channels_);
  }
  const float* pixel(int x, int y) const { return view().pixel(x, y); }
  float& at(int x, int y, int c) { return pixel(x, y)[c]; }
  float at(int x, int y, int c) const { return pixel(x, y)[c]; }

  ImageView view() const { return ImageView{data_.data(), width_, height_, channels_}; }

  // Optional channel names ("R", "ViewLayer.Vector.X", ...), one per channel.
  std::vector<std::string> channel_names;

 private:
  int width_ = 0;
  int height_ = 0;
  int channels_ = 0;
  std::vector<float> data_;
};

// Validation helpers: each throws ValueError with a message naming `what`.
void require_nonempty(const ImageView& image, std::string_view what);
void require_finite(const ImageView& image, std::string_view what);
void require_same_size(const ImageView& a, std::string_view a_what, const ImageView& b,
                       std::string_view b_what);

// Channels [first, first + count) of `image` as a new image.
Image extract_channels(const ImageView& image, int first, int count);

}  // namespace tempera

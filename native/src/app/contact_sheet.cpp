#include "tempera/app/contact_sheet.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "tempera/engine/error.hpp"
#include "tempera/app/image_io.hpp"

namespace tempera {
namespace {

int common_channels(const std::vector<ImageView>& images) {
  std::set<int> counts;
  for (std::size_t i = 0; i < images.size(); ++i) {
    if (images[i].empty())
      throw ValueError(concat("contact_sheet: image ", i, " must be a non-empty (H, W) or (H, W, C) array, got ",
                              images[i].height, "x", images[i].width, "x", images[i].channels));
    counts.insert(images[i].channels);
  }
  const int channels = *counts.rbegin();
  counts.erase(1);
  counts.erase(channels);
  if (!counts.empty()) {
    std::string list;
    for (const auto& image : images) list += concat(list.empty() ? "" : ", ", image.channels);
    throw ValueError(concat("contact_sheet: images have different channel counts (", list, ")"));
  }
  return channels;
}

// Copies `image` with its top-left corner at (x0, y0); grey repeats to all channels.
void paste(Image& sheet, const ImageView& image, int x0, int y0) {
  const int channels = sheet.channels();
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      float* out = sheet.pixel(x0 + x, y0 + y);
      const float* in = image.pixel(x, y);
      for (int c = 0; c < channels; ++c) out[c] = in[image.channels == 1 ? 0 : c];
    }
}

}  // namespace

Image contact_sheet(const std::vector<ImageView>& images, const ContactSheetLayout& layout) {
  if (images.empty()) throw ValueError("contact_sheet: no images given");
  if (layout.gap < 0 || layout.margin < 0)
    throw ValueError(concat("contact_sheet: gap and margin must be >= 0, got gap=", layout.gap,
                            ", margin=", layout.margin));
  if (layout.columns < 0) throw ValueError(concat("contact_sheet: columns must be >= 1, got ", layout.columns));
  const int n = int(images.size());
  const int channels = common_channels(images);
  if (layout.background.size() != 1 && int(layout.background.size()) != channels)
    throw ValueError(concat("contact_sheet: background must be one value or ", channels, " values, got ",
                            layout.background.size()));
  const int columns = std::min(layout.columns > 0 ? layout.columns : int(std::ceil(std::sqrt(double(n)))), n);
  const int rows = (n + columns - 1) / columns;
  int cell_w = 0, cell_h = 0;
  for (const auto& image : images) cell_w = std::max(cell_w, image.width), cell_h = std::max(cell_h, image.height);
  Image sheet(2 * layout.margin + columns * cell_w + (columns - 1) * layout.gap,
              2 * layout.margin + rows * cell_h + (rows - 1) * layout.gap, channels);
  for (std::size_t i = 0; i < sheet.pixel_count(); ++i)
    for (int c = 0; c < channels; ++c)
      sheet.data()[i * channels + c] = layout.background[layout.background.size() == 1 ? 0 : c];
  for (int i = 0; i < n; ++i) {
    const int row = i / columns, col = i % columns;
    paste(sheet, images[i], layout.margin + col * (cell_w + layout.gap) + (cell_w - images[i].width) / 2,
          layout.margin + row * (cell_h + layout.gap) + (cell_h - images[i].height) / 2);
  }
  return sheet;
}

namespace {
constexpr int kSheetMaxWidth = 2000;
constexpr int kSheetGap = 4;
}  // namespace

void write_frames_contact_sheet(const std::string& path, const ImageView& first, const std::vector<std::string>& files,
                                int columns) {
  std::vector<std::pair<int, int>> sizes = {{first.width, first.height}};
  for (const std::string& file : files) {
    const ImageFileInfo info = inspect_image(file);
    sizes.push_back({info.width, info.height});
  }
  const int n = int(sizes.size());
  const int cols = std::min(columns > 0 ? columns : int(std::ceil(std::sqrt(double(n)))), n);
  const int rows = (n + cols - 1) / cols;
  int widest = 0;
  for (const auto& [w, h] : sizes) widest = std::max(widest, w);
  const double scale = std::min(1.0, double(kSheetMaxWidth - (cols - 1) * kSheetGap) / (double(cols) * widest));
  auto scaled = [&](int v) { return scale < 1.0 ? std::max(1, int(std::floor(v * scale))) : v; };
  int cell_w = 0, cell_h = 0;
  for (const auto& [w, h] : sizes) cell_w = std::max(cell_w, scaled(w)), cell_h = std::max(cell_h, scaled(h));
  const int channels = first.channels == 1 ? 3 : first.channels;
  Image sheet(cols * cell_w + (cols - 1) * kSheetGap, rows * cell_h + (rows - 1) * kSheetGap, channels);
  std::fill(sheet.data(), sheet.data() + sheet.pixel_count() * channels, 1.0f);  // white paper between the paintings
  auto paste = [&](const ImageView& full, int i) {
    Image small;
    ImageView image = full;
    if (scaled(full.width) != full.width || scaled(full.height) != full.height) {
      small = resize_image(full, scaled(full.width), scaled(full.height));
      image = small.view();
    }
    const int x0 = (i % cols) * (cell_w + kSheetGap) + (cell_w - image.width) / 2;
    const int y0 = (i / cols) * (cell_h + kSheetGap) + (cell_h - image.height) / 2;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        float* out = sheet.pixel(x0 + x, y0 + y);
        const float* in = image.pixel(x, y);
        for (int c = 0; c < channels; ++c) out[c] = in[image.channels == 1 ? 0 : std::min(c, image.channels - 1)];
        if (channels == 4 && image.channels < 4) out[3] = 1.0f;
      }
  };
  paste(first, 0);
  for (std::size_t i = 0; i < files.size(); ++i) paste(read_image(files[i]).view(), int(i) + 1);
  write_image(path, sheet.view());
}

}  // namespace tempera

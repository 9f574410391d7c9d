#pragma once
// Contact sheets: many same-kind images laid out on one grid.
#include <string>
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

// Lays `images` out row by row, each centred in a cell as large as the
// largest image, `gap` pixels apart, `margin` around; columns 0 =
// ceil(sqrt(n)). Single-channel images are repeated to the common channel
// count. `background` holds 1 or C values. (tempera.contact_sheet.)
struct ContactSheetLayout {
  int columns = 0;
  int gap = 4;
  int margin = 0;
  std::vector<float> background = {0.0f};
};
Image contact_sheet(const std::vector<ImageView>& images, const ContactSheetLayout& layout = {});

// A job's sheet: `first` (the painting, the exemplar) followed by the image
// `files` (the frames written so far), downscaled so that the sheet stays
// within about 2000 pixels wide, white between the images; columns 0 = auto.
// Written atomically.
void write_frames_contact_sheet(const std::string& path, const ImageView& first, const std::vector<std::string>& files,
                                int columns = 0);

}  // namespace tempera

#include "tempera/app/light_path_shot.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "tempera/app/contact_sheet.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/app/paths.hpp"
#include "tempera/app/file_keys.hpp"
#include "tempera/engine/error.hpp"

namespace fs = std::filesystem;

namespace tempera {
namespace {

void require_file(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw FileNotFoundError(concat(what, " not found: '", path, "'"));
}

void require_folder(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) throw FileNotFoundError(concat(what, " folder not found: '", path, "'"));
}

// The painting at the exemplar guides' size: same aspect within 1% is
// resampled (a photo of the template rarely lands on the exact pixel size).
Image fit_painting(Image painting, const std::string& path, int width, int height,
                   std::vector<std::string>& warnings) {
  if (painting.width() == width && painting.height() == height) return painting;
  const double aspect = double(painting.width()) / painting.height(), target = double(width) / height;
  if (std::abs(aspect / target - 1.0) > 0.01)
    throw ValueError(concat("the painting '", path, "' is ", painting.width(), "x", painting.height(),
                            " but the exemplar guides are ", width, "x", height,
                            "; the aspect ratios differ (paint on the exemplar's template)"));
  warnings.push_back(concat("the painting '", path, "' is ", painting.width(), "x", painting.height(),
                            "; resampled to the exemplar guides' ", width, "x", height));
  return resize_image(painting.view(), width, height);
}

bool has_guide(const ImageFileInfo& info, const std::string& guide) {
  return std::any_of(info.channel_names.begin(), info.channel_names.end(),
                     [&](const std::string& c) { return c.rfind(guide + ".", 0) == 0; });
}

}  // namespace

LightPathShot::LightPathShot(const LightPathShotConfig& config, const std::vector<std::string>& guides,
                             std::vector<std::string>& warnings)
    : config_(config), guides_(guides) {
  if (config_.prefix.find('/') != std::string::npos)
    throw ValueError(concat("prefix '", config_.prefix, "' must not contain '/'"));
  require_file(config_.exemplar, "painting");
  if (config_.exemplar_guides.empty())
    throw ValueError("--exemplar-guides is required (the guide cache of the exemplar render)");
  require_folder(config_.exemplar_guides, "exemplar guide");
  exemplar_path_ =
      guide_cache_frame(config_.exemplar_guides, exemplar_guide_frame(config_.exemplar_guides, config_.exemplar_frame));
  require_file(exemplar_path_, "exemplar guide frame");
  exemplar_ = GuideFrame::read(exemplar_path_, guides);
  const Image& first = exemplar_.get(guides.front());
  Image painting = read_image(config_.exemplar);
  require_finite(painting.view(), concat("the painting '", config_.exemplar, "'"));
  style_ = fit_painting(std::move(painting), config_.exemplar, first.width(), first.height(), warnings);

  require_folder(config_.guides, "guide cache");
  std::string missing;
  for (int frame : config_.frames) {
    std::error_code ec;
    if (!fs::is_regular_file(target_path(frame), ec)) missing += concat(missing.empty() ? "" : ", ", frame);
  }
  if (!missing.empty())
    throw FileNotFoundError(concat("the guide cache '", config_.guides, "' has no frame_####.exr for frame(s) ",
                                   missing, " (render them with tempera render-guides)"));
  for (int frame : config_.frames) {
    const std::string path = target_path(frame);
    const ImageFileInfo info = inspect_image(path);
    for (const auto& name : guides)
      if (!has_guide(info, name)) throw ValueError(concat("guide '", name, "' missing from '", path, "'"));
    has_motion_.push_back(has_guide(info, "velocity_backward") && has_guide(info, "occlusion_backward"));
  }

  // Nothing may be written onto the guides or the painting: refuse before anything is.
  inputs_.add_folder(config_.guides, "guide cache", "the guides");
  inputs_.add_folder(config_.exemplar_guides, "exemplar guide cache", "the guides");
  inputs_.add_file(config_.exemplar, "painting");
  inputs_.add_file(exemplar_path_, "exemplar guide frame");
  for (int frame : config_.frames) inputs_.add_file(target_path(frame), "guide frame");
  inputs_.refuse_folder(config_.out);
  for (int frame : config_.frames) inputs_.refuse_file(output_path(frame));
}

void LightPathShot::prepare_output() const {
  create_output_folder(config_.out);
  remove_stale_temporaries(config_.out);
}

std::string LightPathShot::target_path(int frame) const { return guide_cache_frame(config_.guides, frame); }

std::string LightPathShot::output_path(int frame) const {
  return (fs::path(config_.out) / frame_file(config_.prefix, frame, config_.format)).string();
}

// The sheet is laid out from the files' headers, then each frame is read,
// downscaled and pasted in turn: memory holds the sheet and one frame, not
// every frame at full float resolution.
void LightPathShot::write_contact_sheet(const std::string& path, int columns) const {
  inputs_.refuse_file(path);
  std::vector<std::string> files;
  std::error_code ec;
  for (int frame : config_.frames)
    if (fs::is_regular_file(output_path(frame), ec)) files.push_back(output_path(frame));
  write_frames_contact_sheet(path, style_.view(), files, columns);
}

}  // namespace tempera

#include "tempera/methods/lazyfluids/lazyfluids_job.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <sstream>

#include "tempera/app/contact_sheet.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/app/file_keys.hpp"
#include "tempera/app/guide_cache.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/app/paths.hpp"
#include "tempera/app/record.hpp"

namespace fs = std::filesystem;

namespace tempera {
namespace {

// 2: the record names its files (app/record.hpp); records of 1 are made again once.
constexpr const char* kRecordFormat = "tempera-lazyfluids-frame 2";
constexpr const char* kStateFolder = "tempera_lazyfluids";
const char* const kFlowGuides[] = {"fluid_velocity", "velocity_forward"};

bool is_image_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".png" || ext == ".exr" || ext == ".tif" || ext == ".tiff" || ext == ".jpg" || ext == ".jpeg";
}

// The exemplar's files: the image itself, or a folder's images sorted by name.
std::vector<std::string> exemplar_files(const std::string& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return {path};
  if (!fs::is_directory(path, ec)) throw FileNotFoundError(concat("exemplar not found: '", path, "'"));
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(path, ec))
    if (entry.is_regular_file() && is_image_file(entry.path()) && entry.path().filename().string()[0] != '.')
      files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw ValueError(concat("the exemplar folder '", path, "' has no image files (PNG, EXR, TIFF)"));
  return files;
}

Image read_rgba(const std::string& file) {
  Image image = read_image(file);
  if (image.channels() != 4)
    throw ValueError(concat("the exemplar '", file, "' has ", image.channels(),
                            " channel(s); LazyFluids needs RGBA (the alpha is the fluid's shape)"));
  require_finite(image.view(), concat("the exemplar '", file, "'"));
  return image;
}

bool has_guide(const ImageFileInfo& info, const std::string& guide) {
  return std::any_of(info.channel_names.begin(), info.channel_names.end(),
                     [&](const std::string& c) { return c.rfind(guide + ".", 0) == 0; });
}

std::string frame_list(const std::vector<int>& frames) {
  std::string out;
  for (int f : frames) out += concat(out.empty() ? "" : ", ", f);
  return out;
}


void check_config(const LazyFluidsJobConfig& c) {
  validate(c.options);
  check_job_config(c, FrameOrder::Consecutive,
                   "LazyFluids needs consecutive frames (each is advected from the one before)");
  std::error_code ec;
  if (!fs::is_directory(c.guides, ec)) throw FileNotFoundError(concat("guide cache folder not found: '", c.guides, "'"));
}

}  // namespace

LazyFluidsJob::LazyFluidsJob(LazyFluidsJobConfig config) : config_(std::move(config)) {
  check_config(config_);
  exemplar_files_ = exemplar_files(config_.exemplar);
  for (const std::string& file : exemplar_files_) {
    exemplar_.push_back(read_rgba(file));
    require_same_size(exemplar_.back().view(), concat("exemplar frame '", file, "'"), exemplar_.front().view(),
                      "the first exemplar frame");
  }
  std::vector<int> fallback, zero;
  int width = 0, height = 0;
  for (int f : config_.frames) {
    const std::string path = guide_path(f);
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
      throw FileNotFoundError(concat("the guide cache '", config_.guides, "' has no frame_####.exr for frame ", f));
    const ImageFileInfo info = inspect_image(path);
    if (!has_guide(info, "alpha")) throw ValueError(concat("LazyFluids needs the 'alpha' guide in '", path, "'"));
    if (f != config_.frames.front() && (info.width != width || info.height != height))
      throw ValueError(concat("frame ", f, "'s guides are ", info.width, "x", info.height, " but frame ",
                              config_.frames.front(), "'s are ", width, "x", height));
    width = info.width, height = info.height;
    const auto guide = std::find_if(std::begin(kFlowGuides), std::end(kFlowGuides),
                                    [&](const char* g) { return has_guide(info, g); });
    flow_guide_.push_back(guide == std::end(kFlowGuides) ? "" : *guide);
    if (flow_guide_.back().empty()) zero.push_back(f);
    else if (flow_guide_.back() != kFlowGuides[0]) fallback.push_back(f);
  }
  if (!fallback.empty())
    warnings_.push_back(concat("no fluid_velocity guide in frame(s) ", frame_list(fallback),
                               ": using velocity_forward as the flow"));
  if (!zero.empty())
    warnings_.push_back(concat("no fluid_velocity or velocity_forward guide in frame(s) ", frame_list(zero),
                               ": the flow is zero there (nothing moves)"));
  std::ostringstream s;
  s << kRecordFormat << ";" << settings_text(config_.options, lazyfluids_option_table())
    << settings_text(config_.options.synthesis, synthesis_option_table()) << "format=" << config_.format << ";";
  for (const std::string& file : exemplar_files_) s << file_stamp(file) << ";";
  settings_ = s.str();
  // Nothing may be written onto the guides or the exemplar: refuse before anything is.
  inputs_.add_folder(config_.guides, "guide cache", "the guides");
  std::error_code ec;
  if (fs::is_directory(config_.exemplar, ec)) inputs_.add_folder(config_.exemplar, "exemplar", "the exemplar's frames");
  for (const std::string& file : exemplar_files_) inputs_.add_file(file, "exemplar");
  for (int f : config_.frames) inputs_.add_file(guide_path(f), "guide frame");
  inputs_.refuse_folder(config_.out);
  inputs_.refuse_folder((fs::path(config_.out) / kStateFolder).string());
  for (int f : config_.frames)
    for (const std::string& path : {output_path(f), state_path(f), field_path(f), record_path(f)}) inputs_.refuse_file(path);
}

std::string LazyFluidsJob::guide_path(int frame) const {
  return guide_cache_frame(config_.guides, frame);
}

std::string LazyFluidsJob::output_path(int frame) const {
  return (fs::path(config_.out) / frame_file("frame_", frame, config_.format)).string();
}

std::string LazyFluidsJob::state_path(int frame) const {
  return (fs::path(config_.out) / kStateFolder / frame_file("frame_", frame, "exr")).string();
}

std::string LazyFluidsJob::field_path(int frame) const {
  return (fs::path(config_.out) / kStateFolder / frame_file("field_", frame, "exr")).string();
}

std::string LazyFluidsJob::record_path(int frame) const {
  return (fs::path(config_.out) / kStateFolder / frame_file("frame_", frame, "txt")).string();
}

// Everything frame `index` depends on: the settings and exemplar, its own and
// the previous frame's guide files, its index (the video exemplar's frame)
// and the exact previous state.
std::string LazyFluidsJob::frame_key(std::size_t index) const {
  const int f = config_.frames[index];
  std::string text = concat(settings_, "\nframe ", f, " index ", index, "\n", file_stamp(guide_path(f)));
  if (index > 0) {
    const FileDigest previous = file_digest(state_path(f - 1));
    text += concat("\n", file_stamp(guide_path(f - 1)), "\nprevious ", previous.size, " ", previous.checksum);
    if (warm_starts(config_.options)) {
      const FileDigest field = file_digest(field_path(f - 1));
      text += concat("\nprevious field ", field.size, " ", field.checksum);
    }
  }
  return hash_hex(text);
}

bool LazyFluidsJob::is_current(std::size_t index) const {
  const int f = config_.frames[index];
  return config_.resume &&
         record_current(record_path(f), kRecordFormat, frame_key(index), {output_path(f), state_path(f)});
}

Image LazyFluidsJob::read_flow(int frame) const {
  const std::size_t index = std::size_t(frame - config_.frames.front());
  const std::string& guide = flow_guide_[index];
  if (guide.empty()) {
    const ImageFileInfo info = inspect_image(guide_path(frame));
    return Image(info.width, info.height, 2, 0.0f);
  }
  return Image::copy_of(GuideFrame::read(guide_path(frame), {guide}).get(guide).view());
}

FrameResult LazyFluidsJob::make_frame(std::size_t index, const ProgressCallback& progress) {
  const int f = config_.frames[index];
  FrameResult result;
  result.frame = f;
  result.path = output_path(f);
  const auto t0 = std::chrono::steady_clock::now();
  const Image alpha = Image::copy_of(GuideFrame::read(guide_path(f), {"alpha"}).get("alpha").view());
  // The exact float state, never the 8-bit output: resumed == uninterrupted.
  const Image flow_previous = index == 0 ? Image() : read_flow(f - 1);
  const Image advected = index == 0 ? Image() : advect_output(read_image(state_path(f - 1)).view(), flow_previous.view());
  const std::size_t m = exemplar_.size();
  FluidFrameInput in;
  in.style = exemplar_[index % m].view();
  in.previous_style = exemplar_[index == 0 ? 0 : (index - 1) % m].view();
  in.target_alpha = alpha.view();
  if (index > 0) in.advected = advected.view();
  OffsetField previous_field;
  std::error_code ec;
  if (index > 0 && warm_starts(config_.options) && fs::is_regular_file(field_path(f - 1), ec)) {
    previous_field = field_from_positions(read_image(field_path(f - 1)).view());
    in.previous_field = &previous_field;
    in.flow_previous = flow_previous.view();
  }
  const FluidFrameResult frame = stylize_fluid_frame(in, config_.options, progress);
  write_frame(index, frame);
  result.status = "stylized";
  result.source_coverage = frame.synthesis.source_coverage;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

// The state, the output (motion-blurred when asked) and then the record,
// each atomically: a crash leaves either no record or a matching one.
void LazyFluidsJob::write_frame(std::size_t index, const FluidFrameResult& frame) const {
  const int f = config_.frames[index];
  const Image& state = frame.image;
  create_output_folder((fs::path(config_.out) / kStateFolder).string());
  std::error_code ec;
  if (warm_starts(config_.options) && !frame.synthesis.field.x.empty())
    write_image(field_path(f), field_positions(frame.synthesis.field).view());
  else
    fs::remove(field_path(f), ec);  // an empty frame: the next one starts cold
  const float blur = config_.options.motion_blur;
  const Image output = blur > 0 ? motion_blur_along_flow(state.view(), read_flow(f).view(), blur) : Image();
  write_image(state_path(f), state.view());
  write_image(output_path(f), blur > 0 ? output.view() : state.view());
  write_record(record_path(f), kRecordFormat, frame_key(index), {output_path(f), state_path(f)});
}

void LazyFluidsJob::write_contact_sheet(const std::string& path, int columns) const {
  inputs_.refuse_file(path);
  std::vector<std::string> files;
  std::error_code ec;
  for (int frame : config_.frames)
    if (fs::is_regular_file(output_path(frame), ec)) files.push_back(output_path(frame));
  write_frames_contact_sheet(path, exemplar_.front().view(), files, columns);
}

}  // namespace tempera

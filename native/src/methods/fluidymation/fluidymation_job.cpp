#include "tempera/methods/fluidymation/fluidymation_job.hpp"

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

// 2: frames made since flows from masks keep a symmetric window at the shot's ends and
// fractional exemplar times vote blended (earlier records are recomputed once).
// 3: the record holds the digests of the frame and its matches (app/record.hpp), so a
// changed or damaged output is made again.
constexpr const char* kRecordFormat = "tempera-fluidymation-frame 3";

bool is_image_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".png" || ext == ".exr" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff";
}

std::vector<std::string> image_files(const std::string& folder, const char* what) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw FileNotFoundError(concat(what, " folder not found: '", folder, "'"));
  std::vector<std::string> out;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.is_regular_file() && is_image_file(entry.path()) && entry.path().filename().string()[0] != '.')
      out.push_back(entry.path().string());
  std::sort(out.begin(), out.end());
  if (out.size() < 2) throw ValueError(concat(what, " folder '", folder, "' needs at least 2 frames, has ", out.size()));
  return out;
}

Image channel(const Image& image, int c) { return extract_channels(image.view(), c, 1); }

bool has_layer(const ImageFileInfo& info, const std::string& layer) {
  return std::any_of(info.channel_names.begin(), info.channel_names.end(),
                     [&](const std::string& n) { return n == layer || n.rfind(layer + ".", 0) == 0; });
}

}  // namespace

FluidymationJob::~FluidymationJob() = default;

namespace {

// The guide of `flow` in the frame `path` described by `info`; "" = from the
// masks. Auto prefers fluid_velocity: on smoke velocity_forward is zero.
std::string pick_flow_guide(FlowSource flow, const ImageFileInfo& info, const std::string& path) {
  const auto required = [&](const char* guide, const char* choice) {
    if (!has_layer(info, guide))
      throw ValueError(concat("--flow ", choice, " needs ", guide, " in the guide cache ('", path, "' has none)"));
    return std::string(guide);
  };
  switch (flow) {
    case FlowSource::Fluid: return required("fluid_velocity", "fluid");
    case FlowSource::Guides: return required("velocity_forward", "guides");
    case FlowSource::Masks: return "";
    case FlowSource::Auto: break;
  }
  for (const char* guide : {"fluid_velocity", "velocity_forward"})
    if (has_layer(info, guide)) return guide;
  return "";
}

}  // namespace

FluidymationJob::FluidymationJob(FluidymationJobConfig c) : config_(std::move(c)) {
  validate(config_.options);
  check_job_config(config_, FrameOrder::Consecutive,
                   "Fluidymation needs consecutive frames (each starts from the one before)");
  if (config_.frames.size() < 2) throw ValueError("Fluidymation needs at least 2 consecutive frames");
  if (config_.target_mask != "alpha" && config_.target_mask.rfind("mask.OB_", 0) != 0 &&
      config_.target_mask.rfind("mask.CO_", 0) != 0)
    throw ValueError(concat("target mask '", config_.target_mask, "' must be alpha, mask.OB_<object> or mask.CO_<collection>"));
  // The exemplar.
  const std::vector<std::string> files = image_files(config_.exemplar, "exemplar");
  std::vector<std::string> mask_files;
  if (!config_.exemplar_masks.empty()) {
    mask_files = image_files(config_.exemplar_masks, "exemplar mask");
    if (mask_files.size() != files.size())
      throw ValueError(concat("the exemplar has ", files.size(), " frames but ", mask_files.size(), " masks"));
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    const Image frame = read_image(files[i]);
    if (frame.channels() < 3) throw ValueError(concat("exemplar frame '", files[i], "' must be RGB or RGBA"));
    if (mask_files.empty() && frame.channels() < 4)
      throw ValueError(concat("exemplar frame '", files[i], "' has no alpha; give its masks (--exemplar-masks)"));
    Image mask = mask_files.empty() ? channel(frame, 3) : channel(read_image(mask_files[i]), 0);
    require_same_size(mask.view(), "exemplar mask", frame.view(), files[i]);
    if (!exemplar_.empty()) require_same_size(frame.view(), files[i], exemplar_[0].view(), files[0]);
    exemplar_.push_back(extract_channels(frame.view(), 0, 3));
    exemplar_masks_.push_back(std::move(mask));
  }
  // The target.
  std::vector<std::string> inputs = files;
  inputs.insert(inputs.end(), mask_files.begin(), mask_files.end());
  for (int f : config_.frames) {
    const std::string path = guide_cache_frame(config_.guides, f);
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw FileNotFoundError(concat("guide cache frame not found: '", path, "'"));
    const ImageFileInfo info = inspect_image(path);
    if (!has_layer(info, config_.target_mask))
      throw ValueError(concat("guide cache frame '", path, "' has no '", config_.target_mask, "' guide"));
    if (f == config_.frames.front()) flow_guide_ = pick_flow_guide(config_.flow, info, path);
    target_masks_.push_back(channel(read_image_layer(path, config_.target_mask), 0));
    if (!flow_guide_.empty()) target_flows_.push_back(read_image_layer(path, flow_guide_));
    inputs.push_back(path);
  }
  // Nothing may be written onto the guides, the exemplar or its masks: refuse before anything is.
  inputs_.add_folder(config_.guides, "guide cache", "the guides");
  inputs_.add_folder(config_.exemplar, "exemplar", "the exemplar's frames");
  if (!config_.exemplar_masks.empty())
    inputs_.add_folder(config_.exemplar_masks, "exemplar mask", "the exemplar's masks");
  for (const std::string& file : files) inputs_.add_file(file, "exemplar frame");
  for (const std::string& file : mask_files) inputs_.add_file(file, "exemplar mask");
  for (int f : config_.frames) inputs_.add_file(guide_cache_frame(config_.guides, f), "guide frame");
  inputs_.refuse_folder(config_.out);
  inputs_.refuse_folder((fs::path(config_.out) / "tempera_fluidymation").string());
  for (int f : config_.frames)
    for (const std::string& path : {output_path(f), state_path(f), record_path(f)}) inputs_.refuse_file(path);
  std::ostringstream base;
  base << settings_text(config_.options, fluidymation_option_table())
       << settings_text(config_.options.synthesis, synthesis_option_table()) << "format=" << config_.format
       << ";mask=" << config_.target_mask << ";flow=" << (flow_guide_.empty() ? "masks" : flow_guide_) << ";frames="
       << config_.frames.front() << "-" << config_.frames.back();
  for (const std::string& in : inputs) base << "\n" << file_stamp(in);
  std::string previous = hash_hex(base.str());
  for (int f : config_.frames) keys_.push_back(previous = hash_hex(concat(previous, "\n", f)));
}

std::string FluidymationJob::output_path(int frame) const {
  return (fs::path(config_.out) / frame_file("frame_", frame, config_.format)).string();
}
std::string FluidymationJob::state_path(int frame) const {
  return (fs::path(config_.out) / "tempera_fluidymation" / frame_file("nnf_", frame, "exr")).string();
}
std::string FluidymationJob::record_path(int frame) const {
  return (fs::path(config_.out) / "tempera_fluidymation" / frame_file("frame_", frame, "txt")).string();
}

bool FluidymationJob::is_current(std::size_t index) const {
  const int f = config_.frames[index];
  return config_.resume && record_current(record_path(f), kRecordFormat, keys_[index], {output_path(f), state_path(f)});
}

FluidSequence FluidymationJob::sequence() const {
  FluidSequence seq;
  for (const Image& i : exemplar_) seq.exemplar.push_back(i.view());
  for (const Image& i : exemplar_masks_) seq.exemplar_masks.push_back(i.view());
  for (const Image& i : target_masks_) seq.target_masks.push_back(i.view());
  for (const Image& i : target_flows_) seq.target_flows.push_back(i.view());
  return seq;
}

const Fluidymation& FluidymationJob::method() {
  if (!method_) method_ = std::make_unique<Fluidymation>(sequence(), config_.options);
  return *method_;
}

void FluidymationJob::write_frame(std::size_t index, const FluidFrame& r) {
  const int f = config_.frames[index];
  create_output_folder((fs::path(config_.out) / "tempera_fluidymation").string());
  const Image& mask = target_masks_[index];
  Image rgba(r.image.width(), r.image.height(), 4);
  for (std::size_t q = 0; q < rgba.pixel_count(); ++q) {
    std::copy_n(r.image.data() + 3 * q, 3, rgba.data() + 4 * q);
    rgba.data()[4 * q + 3] = std::clamp(mask.data()[q], 0.0f, 1.0f);
  }
  write_image(output_path(f), rgba.view(), {"R", "G", "B", "A"});
  write_image(state_path(f), r.nnf.view(), {"i", "x", "y", "phi"});
  write_record(record_path(f), kRecordFormat, keys_[index], {output_path(f), state_path(f)});
}

FrameResult FluidymationJob::make_frame(std::size_t index, const ProgressCallback& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  FrameResult result;
  result.frame = config_.frames[index];
  result.path = output_path(result.frame);
  if (config_.options.bidirectional) {
    if (both_ways_.empty()) both_ways_ = stylize_fluid_sequence(sequence(), config_.options, progress);
    write_frame(index, both_ways_[index]);
  } else {
    FluidNnf loaded;
    if (index > 0 && last_index_ != index - 1)  // the predecessor is current on disk (ChainedFrameJob)
      loaded = read_image(state_path(config_.frames[index - 1]), {"i", "x", "y", "phi"});
    const FluidNnf* previous = index == 0 ? nullptr : last_index_ == index - 1 ? &last_nnf_ : &loaded;
    FluidFrame r = method().solve_frame(int(index), previous, progress);
    write_frame(index, r);
    last_nnf_ = std::move(r.nnf);
    last_index_ = index;
  }
  result.status = "stylized";
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

void FluidymationJob::write_contact_sheet(const std::string& path, int columns) const {
  inputs_.refuse_file(path);
  std::vector<Image> images;
  Image first(exemplar_[0].width(), exemplar_[0].height(), 4);
  for (std::size_t q = 0; q < first.pixel_count(); ++q) {
    std::copy_n(exemplar_[0].data() + 3 * q, 3, first.data() + 4 * q);
    first.data()[4 * q + 3] = exemplar_masks_[0].data()[q] > 0.5f ? 1.0f : 0.0f;
  }
  images.push_back(std::move(first));
  std::error_code ec;
  for (int f : config_.frames)
    if (fs::is_regular_file(output_path(f), ec)) images.push_back(read_image(output_path(f), {"R", "G", "B", "A"}));
  std::vector<ImageView> views;
  for (const Image& i : images) views.push_back(i.view());
  ContactSheetLayout layout;
  layout.columns = columns;
  layout.background = {1.0f, 1.0f, 1.0f, 0.0f};
  write_image(path, contact_sheet(views, layout).view());
}

}  // namespace tempera

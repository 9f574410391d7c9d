#include "tempera/methods/noisy/noisy_sequence.hpp"

#include <chrono>
#include <filesystem>

#include "tempera/engine/color.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/app/contact_sheet.hpp"
#include "tempera/app/file_keys.hpp"
#include "tempera/app/guide_cache.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/app/record.hpp"
#include "tempera/app/light_path_guides.hpp"
#include "tempera/methods/noisy/render_medium.hpp"

namespace fs = std::filesystem;

namespace tempera {
namespace {

// The guide that is the render (Cycles' Combined pass, app/light_path_guides.hpp).
constexpr const char* kRenderGuide = "FULL";

// The format line of a frame's resume record (app/record.hpp). Before it,
// the record was the bare key: such frames are made again once.
constexpr const char* kRecordFormat = "tempera-noisy-frame 1";

fs::path record_path(const std::string& out, int frame) {
  return fs::path(out) / ".tempera_noisy" / frame_file("", frame, "key");
}

}  // namespace

NoisySequence::NoisySequence(NoisySequenceConfig config) : config_(std::move(config)) {
  const NoisySequenceConfig& c = config_;
  validate_noisy_options(c.options);
  validate(c.options.synthesis);
  check_job_config(c);
  if (c.format != "png") throw ValueError(concat("the noise pass writes PNG frames, not '", c.format, "'"));
  if (c.exemplar.empty() && !renders())
    throw ValueError("the exemplar (a sample of the medium) is required to boil frames of a folder");
  if (renders() && c.guides.empty())
    throw ValueError("the coherent frames are required: a folder of them, or a guide cache whose render is boiled");
  const std::string folder = renders() ? c.guides : c.reference;
  if (!fs::is_directory(folder))
    throw FileNotFoundError(concat(renders() ? "the guide cache '" : "the reference folder '", folder,
                                   "' does not exist"));
  for (int frame : c.frames)
    if (!fs::is_regular_file(reference_path(frame)))
      throw FileNotFoundError(concat(renders() ? "guide frame not found: '" : "reference frame not found: '",
                                     reference_path(frame), "'"));
  refuse_writing_on_inputs();
  settings_ = settings_text(c.options, noisy_option_table()) +
              settings_text(c.options.synthesis, synthesis_option_table()) + (renders() ? "|render" : "");
  // The first render, read once: the default medium's colours, and it names a
  // cache without a render, or a medium of other channels, now, not after hours.
  const Image first = renders() ? reference_frame(c.frames.front()) : Image();
  if (c.exemplar.empty()) {  // the first render under a paper grain (render_medium.hpp)
    medium_ = render_medium(first.view(), c.options.synthesis.seed);
    settings_ += "|medium from " + file_stamp(reference_path(c.frames.front()));
  } else {
    medium_ = read_image(c.exemplar);
    settings_ += file_stamp(c.exemplar);
  }
  check_noisy_exemplar_size(c.options.noise, medium_.width(), medium_.height(), c.options.synthesis.patch_size);
  if (renders() && first.channels() != medium_.channels())
    throw ValueError(concat("the render has ", first.channels(), " channels but the exemplar '", c.exemplar,
                            "' has ", medium_.channels(), " (give an RGB sample of the medium)"));
  if (guided()) read_exemplar_guides();
  if (!c.noise_map.empty()) {
    map_file_ = fs::is_regular_file(c.noise_map);
    if (map_file_) {
      file_map_ = extract_channels(read_image(c.noise_map).view(), 0, 1);
      settings_ += "|map " + file_stamp(c.noise_map);
    } else if (c.guides.empty()) {
      throw ValueError(concat("the noise map '", c.noise_map,
                              "' is neither an image file nor a guide (a guide needs the guide cache folder)"));
    } else {
      settings_ += "|guide map " + c.noise_map;
      noise_map(c.frames.front());  // names a missing guide now, not after hours
    }
  }
}

// Nothing may be written onto the reference frames, the medium, the noise
// map or the guides: refuse before anything is.
void NoisySequence::refuse_writing_on_inputs() {
  const NoisySequenceConfig& c = config_;
  if (!renders()) inputs_.add_folder(c.reference, "reference", "the coherent frames");
  inputs_.add_folder(c.guides, "guide cache", "the guides");
  inputs_.add_folder(c.exemplar_guides, "exemplar guide cache", "the guides");
  inputs_.add_file(c.exemplar, "exemplar");
  inputs_.add_file(c.noise_map, "noise map");
  for (int frame : c.frames) {
    inputs_.add_file(reference_path(frame), "reference frame");
    if (!c.guides.empty()) inputs_.add_file(guide_path(frame), "guide frame");
  }
  inputs_.refuse_folder(c.out);
  for (int frame : c.frames) {
    inputs_.refuse_file(output_path(frame));
    inputs_.refuse_file(record_path(c.out, frame).string());
  }
}

// Guided noise: the active light-path guides and the exemplar's side, read
// once; the frame's side is read per frame (and its file is in the key).
void NoisySequence::read_exemplar_guides() {
  const NoisySequenceConfig& c = config_;
  if (c.guides.empty()) throw ValueError("guided noise (noise_guides > 0) needs the frames' guide cache (--guides)");
  if (c.exemplar_guides.empty())
    throw ValueError("guided noise (noise_guides > 0) needs the exemplar's guide cache (--exemplar-guides)");
  if (!fs::is_directory(c.exemplar_guides))
    throw FileNotFoundError(concat("the exemplar guide folder '", c.exemplar_guides, "' does not exist"));
  light_path_ = active_guides(c.guide_weights);
  std::vector<std::string> names;
  for (const auto& [name, weight] : light_path_) names.push_back(name);
  const std::string path =
      guide_cache_frame(c.exemplar_guides, exemplar_guide_frame(c.exemplar_guides, c.exemplar_frame));
  const GuideFrame exemplar = GuideFrame::read(path, names);
  for (const auto& [name, weight] : light_path_) {
    const Image& g = exemplar.get(name);
    if (g.width() != medium_.width() || g.height() != medium_.height())
      throw ValueError(concat("the exemplar guide '", name, "' of '", path, "' is ", g.width(), "x", g.height(),
                              " but the exemplar '", c.exemplar, "' is ", medium_.width(), "x", medium_.height()));
    exemplar_guides_.push_back(tonemap_guide(g.view()));
    settings_ += concat("|guide ", name, "=", weight);
  }
  settings_ += "|exemplar guides " + file_stamp(path);
  frame_guides(c.frames.front());  // names a missing guide frame now, not after hours
}

std::vector<Image> NoisySequence::frame_guides(int frame) const {
  std::vector<std::string> names;
  for (const auto& [name, weight] : light_path_) names.push_back(name);
  const GuideFrame g = GuideFrame::read(guide_path(frame), names);
  std::vector<Image> out;
  for (const std::string& name : names) out.push_back(tonemap_guide(g.get(name).view()));
  return out;
}

std::string NoisySequence::reference_path(int frame) const {
  if (renders()) return guide_path(frame);
  return (fs::path(config_.reference) / frame_file(config_.prefix, frame, "png")).string();
}

Image NoisySequence::reference_frame(int frame) const {
  if (!renders()) return read_image(reference_path(frame));
  const GuideFrame g = GuideFrame::read(guide_path(frame), {kRenderGuide});
  return linear_to_srgb(g.get(kRenderGuide).view());
}

std::string NoisySequence::guide_path(int frame) const {
  return guide_cache_frame(config_.guides, frame);
}

std::string NoisySequence::output_path(int frame) const {
  return (fs::path(config_.out) / frame_file(config_.prefix, frame, "png")).string();
}

Image NoisySequence::noise_map(int frame) const {
  if (config_.noise_map.empty()) return {};
  if (map_file_) return Image::copy_of(file_map_.view());
  const GuideFrame g = GuideFrame::read(guide_path(frame), {config_.noise_map});
  return extract_channels(g.get(config_.noise_map).view(), 0, 1);
}

std::string NoisySequence::key(int frame) const {
  std::string text = concat(settings_, "|", frame, "|", file_stamp(reference_path(frame)));
  if (map_is_guide() || guided()) text += "|" + file_stamp(guide_path(frame));
  return hash_hex(text);
}

void NoisySequence::write_contact_sheet(const std::string& path, int columns) const {
  inputs_.refuse_file(path);
  std::vector<std::string> files;
  std::error_code ec;
  for (int frame : config_.frames)
    if (fs::is_regular_file(output_path(frame), ec)) files.push_back(output_path(frame));
  write_frames_contact_sheet(path, medium_.view(), files, columns);
}

FrameResult NoisySequence::run_frame(std::size_t index, const ProgressCallback& progress) {
  if (index >= config_.frames.size())
    throw ValueError(concat("frame index ", index, " out of range (", config_.frames.size(), " frames)"));
  const int frame = config_.frames[index];
  FrameResult result;
  result.frame = frame;
  result.path = output_path(frame);
  result.status = "skipped";
  const fs::path record = record_path(config_.out, frame);
  const std::string k = key(frame);
  if (config_.resume && record_current(record.string(), kRecordFormat, k, {result.path})) return result;
  const auto t0 = std::chrono::steady_clock::now();
  const Image r = reference_frame(frame);
  const Image map = noise_map(frame);
  std::vector<Image> targets;
  std::vector<NoisyGuide> guides;
  if (guided()) {
    targets = frame_guides(frame);
    for (std::size_t i = 0; i < targets.size(); ++i)
      guides.push_back({light_path_[i].first, exemplar_guides_[i].view(), targets[i].view(), light_path_[i].second});
  }
  const Image out = noisy_frame(medium_.view(), r.view(), frame, config_.options, map.empty() ? ImageView{} : map.view(),
                                progress, guides);
  fs::create_directories(record.parent_path());
  write_image(result.path, out.view());  // atomic
  write_record(record.string(), kRecordFormat, k, {result.path});
  result.status = "made";
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace tempera

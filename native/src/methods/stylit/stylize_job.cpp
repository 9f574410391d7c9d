#include "tempera/methods/stylit/stylize_job.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "tempera/app/contact_sheet.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/app/file_keys.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/app/paths.hpp"
#include "tempera/app/text_file.hpp"

namespace fs = std::filesystem;

namespace tempera {
namespace {

constexpr const char* kReportName = "tempera_stylize.json";
constexpr const char* kReportFormat = "tempera-stylize 2";

void require_file(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw FileNotFoundError(concat(what, " not found: '", path, "'"));
}

void require_folder(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) throw FileNotFoundError(concat(what, " folder not found: '", path, "'"));
}

// Canonical text of everything that changes a stylized frame but the files.
// Threads are left out: the engine's result does not depend on them.
std::string settings_text(const StylizeJobConfig& c) {
  const SynthesisOptions o = engine_options(c.stylit);
  std::ostringstream s;
  s << "weights=";
  for (const auto& [name, weight] : active_guides(c.stylit)) s << name << ":" << weight << ",";
  s << ";temporal=" << c.stylit.temporal_weight << ";quality=" << enum_name(c.stylit.quality) << ";"
    << settings_text(o, synthesis_option_table()) << "format=" << c.format;
  return s.str();
}

// Temporary files (".<name>.tmp<pid>-<random>...") of writers killed with -9.
// A live writer holds one for the seconds an image takes to write, so one
// older than an hour is dead; it is never read, only removed here.
void remove_stale_temporaries(const std::string& folder) {
  std::error_code ec;
  const auto now = fs::file_time_type::clock::now();
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() < 2 || name[0] != '.' || name.find(".tmp") == std::string::npos) continue;
    std::error_code stat_ec;
    const auto written = fs::last_write_time(it->path(), stat_ec);
    if (!stat_ec && now - written > std::chrono::hours(1) && fs::is_regular_file(it->path(), stat_ec))
      fs::remove(it->path(), stat_ec);
  }
}

void validate_config(const StylizeJobConfig& c) {
  check_job_config(c);
  if (c.prefix.find('/') != std::string::npos) throw ValueError(concat("prefix '", c.prefix, "' must not contain '/'"));
  const SynthesisOptions& o = c.stylit.synthesis;
  if (o.patch_size < 3 || o.patch_size % 2 == 0)
    throw ValueError(concat("patch size must be odd and >= 3, got ", o.patch_size));
  if (o.threads < 0) throw ValueError(concat("threads must be >= 0 (0 = all cores), got ", o.threads));
  active_guides(c.stylit);
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

}  // namespace

StylizeJob::StylizeJob(StylizeJobConfig config)
    : config_(std::move(config)), report_(config_.out, kReportName, kReportFormat) {
  validate_config(config_);
  const auto guides = active_guides(config_.stylit);
  std::vector<std::string> names;
  for (const auto& [name, weight] : guides) names.push_back(name);

  require_file(config_.exemplar, "painting");
  require_folder(config_.exemplar_guides, "exemplar guide");
  exemplar_path_ =
      guide_cache_frame(config_.exemplar_guides, exemplar_guide_frame(config_.exemplar_guides, config_.exemplar_frame));
  require_file(exemplar_path_, "exemplar guide frame");
  exemplar_ = GuideFrame::read(exemplar_path_, names);
  const Image& first = exemplar_.get(names.front());
  Image painting = read_image(config_.exemplar);
  require_finite(painting.view(), concat("the painting '", config_.exemplar, "'"));
  style_ = fit_painting(std::move(painting), config_.exemplar, first.width(), first.height(), warnings_);

  require_folder(config_.guides, "guide cache");
  std::string missing;
  for (int frame : config_.frames) {
    std::error_code ec;
    if (!fs::is_regular_file(target_path(frame), ec)) missing += concat(missing.empty() ? "" : ", ", frame);
  }
  if (!missing.empty())
    throw FileNotFoundError(concat("the guide cache '", config_.guides, "' has no frame_####.exr for frame(s) ",
                                   missing, " (render them with tempera render-guides)"));
  check_target_guides(names);

  // Nothing may be written onto the guides or the painting: refuse before anything is.
  inputs_.add_folder(config_.guides, "guide cache", "the guides");
  inputs_.add_folder(config_.exemplar_guides, "exemplar guide cache", "the guides");
  inputs_.add_file(config_.exemplar, "painting");
  inputs_.add_file(exemplar_path_, "exemplar guide frame");
  for (int frame : config_.frames) inputs_.add_file(target_path(frame), "guide frame");
  inputs_.refuse_folder(config_.out);
  for (int frame : config_.frames) inputs_.refuse_file(output_path(frame));
  inputs_.refuse_file(report_path());
  std::error_code ec;
  fs::create_directories(config_.out, ec);
  if (!fs::is_directory(config_.out, ec))
    throw IoError(concat("cannot create the output folder '", config_.out, "'", ec ? ": " + ec.message() : ""));
  remove_stale_temporaries(config_.out);
  settings_ = settings_text(config_);
  const std::string base = hash_hex(settings_ + "\n" + file_stamp(config_.exemplar) + "\n" + file_stamp(exemplar_path_));
  // The predecessor's result is deliberately not part of a frame's key: frames
  // made on several machines (each chain starting at its own first frame) stay
  // current when one run over the whole range assembles the sheet and video.
  for (int frame : config_.frames)
    keys_.push_back(hash_hex(concat(base, "\n", frame, "\n", file_stamp(target_path(frame)))));
}

// Every target frame has the light-path guides; motion guides are needed for
// the temporal guide and optional for the flicker figure.
void StylizeJob::check_target_guides(const std::vector<std::string>& names) {
  for (std::size_t i = 0; i < config_.frames.size(); ++i) {
    const std::string path = target_path(config_.frames[i]);
    const ImageFileInfo info = inspect_image(path);
    auto has = [&](const std::string& guide) {
      return std::any_of(info.channel_names.begin(), info.channel_names.end(),
                         [&](const std::string& c) { return c.rfind(guide + ".", 0) == 0; });
    };
    for (const auto& name : names)
      if (!has(name)) throw ValueError(concat("guide '", name, "' missing from '", path, "'"));
    const bool motion = has("velocity_backward") && has("occlusion_backward");
    if (!motion && config_.stylit.temporal_weight > 0 && has_temporal_predecessor(i))
      throw ValueError(concat("the temporal guide needs velocity_backward and occlusion_backward, missing from '",
                              path, "'"));
    has_motion_.push_back(motion);
  }
}

std::string StylizeJob::output_path(int frame) const {
  return (fs::path(config_.out) / frame_file(config_.prefix, frame, config_.format)).string();
}

std::string StylizeJob::report_path() const { return report_.path(); }

std::string StylizeJob::target_path(int frame) const { return guide_cache_frame(config_.guides, frame); }

// Velocities of frame f point to frame f - 1, so only that frame can be chained.
bool StylizeJob::has_temporal_predecessor(std::size_t index) const {
  return index > 0 && config_.frames[index - 1] == config_.frames[index] - 1;
}

FrameResult StylizeJob::run_frame(std::size_t index, const ProgressCallback& progress) {
  if (index >= config_.frames.size())
    throw ValueError(concat("frame index ", index, " out of range (the job has ", config_.frames.size(), " frames)"));
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  FrameResult result;
  result.frame = config_.frames[index];
  result.path = output_path(result.frame);
  std::error_code ec;
  if (config_.resume) {
    // Current: same key, and the file is the one written (size and checksum),
    // so a truncated or overwritten output is made again.
    if (const auto done = report_.current(result.frame, keys_[index], result.path, warnings_)) {
      result.status = "skipped";
      result.flicker = done->flicker;
      result.source_coverage = done->source_coverage;
      return result;
    }
  }
  std::vector<std::string> names;
  for (const auto& [name, weight] : active_guides(config_.stylit)) names.push_back(name);
  if (has_motion_[index]) names.insert(names.end(), {"velocity_backward", "occlusion_backward"});
  const GuideFrame target = GuideFrame::read(target_path(result.frame), names);

  // The predecessor as written to disk, whether made now or in an earlier run:
  // a resumed sequence then continues exactly like an uninterrupted one.
  Image previous;
  const std::string previous_path = index > 0 ? output_path(config_.frames[index - 1]) : "";
  if (has_temporal_predecessor(index) && has_motion_[index] && fs::is_regular_file(previous_path, ec))
    previous = read_image(previous_path);
  TemporalInput temporal;
  if (!previous.empty())
    temporal = {previous.view(), target.get("velocity_backward").view(), target.get("occlusion_backward").view()};

  SynthesisResult synth = stylize_frame(style_.view(), exemplar_, target, previous.empty() ? nullptr : &temporal,
                                        config_.stylit, progress);
  write_image(result.path, synth.image.view());
  result.status = "stylized";
  result.source_coverage = synth.source_coverage;
  result.flicker = previous.empty() || previous.channels() != synth.image.channels()
                       ? std::numeric_limits<double>::quiet_NaN()
                       : flicker(previous.view(), synth.image.view(), temporal.velocity_backward,
                                 temporal.occlusion_backward);
  // Other processes and machines may share this folder, each adding its own frames.
  report_.add(result.frame,
              {keys_[index], fs::path(result.path).filename().string(), result.flicker, result.source_coverage,
               file_digest(result.path)},
              settings_, warnings_);
  result.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return result;
}

// The sheet is laid out from the files' headers, then each frame is read,
// downscaled and pasted in turn: memory holds the sheet and one frame, not
// every frame at full float resolution.
void StylizeJob::write_contact_sheet(const std::string& path, int columns) const {
  inputs_.refuse_file(path);
  std::vector<std::string> files;
  std::error_code ec;
  for (int frame : config_.frames)
    if (fs::is_regular_file(output_path(frame), ec)) files.push_back(output_path(frame));
  write_frames_contact_sheet(path, style_.view(), files, columns);
}

}  // namespace tempera

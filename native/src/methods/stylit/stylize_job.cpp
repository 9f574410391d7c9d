#include "tempera/methods/stylit/stylize_job.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

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
constexpr const char* kFieldFolder = "tempera_stylize";  // warm start: each frame's final matches

// Canonical text of everything that changes a stylized frame but the files.
// Threads are left out: the engine's result does not depend on them.
std::string settings_text(const StylizeJobConfig& c) {
  const SynthesisOptions o = engine_options(c.stylit);
  std::ostringstream s;
  s << "weights=";
  for (const auto& [name, weight] : active_guides(c.stylit)) s << name << ":" << weight << ",";
  s << ";temporal=" << c.stylit.temporal_weight << ";quality=" << enum_name(c.stylit.quality) << ";"
    << settings_text(o, synthesis_option_table()) << "format=" << c.format;
  // Frames with the temporal guide are matched on fixed-point features since
  // 2026-12-05 (engine_options): those made before are made again.
  if (c.stylit.temporal_weight > 0 && o.fixed_point_weights) s << ";weights=fixed";
  // Absent when off: the keys of cold frames stay as they were. Warm frames
  // restart disoccluded pixels on the guides since 2026-12-06: older ones are made again.
  if (warm_starts(c.stylit)) s << ";warm_start=guides";
  return s.str();
}

// The shot's inputs read and checked, after the config's own checks.
LightPathShot checked_shot(const StylizeJobConfig& c, std::vector<std::string>& warnings) {
  check_job_config(c);
  const SynthesisOptions& o = c.stylit.synthesis;
  if (o.patch_size < 3 || o.patch_size % 2 == 0)
    throw ValueError(concat("patch size must be odd and >= 3, got ", o.patch_size));
  if (o.threads < 0) throw ValueError(concat("threads must be >= 0 (0 = all cores), got ", o.threads));
  active_guides(c.stylit);  // the temporal weight too
  return LightPathShot(c, active_guide_names(c.stylit.weights), warnings);
}

}  // namespace

StylizeJob::StylizeJob(StylizeJobConfig config)
    : config_(std::move(config)),
      report_(config_.out, kReportName, kReportFormat),
      shot_(checked_shot(config_, warnings_)) {
  check_temporal_guides();
  shot_.inputs().refuse_file(report_path());  // nothing may be written onto an input: refuse before anything is
  if (warm_starts(config_.stylit)) {
    for (int frame : config_.frames) shot_.inputs().refuse_file(field_path(frame));
    if (fs::is_directory(field_folder())) remove_stale_temporaries(field_folder());  // of killed writers, as in OUT
  }
  shot_.prepare_output();
  settings_ = settings_text(config_);
  const std::string base = hash_hex(settings_ + "\n" + file_stamp(config_.exemplar) + "\n" + file_stamp(shot_.exemplar_path()));
  // The predecessor's result is deliberately not part of a frame's key: frames
  // made on several machines (each chain starting at its own first frame) stay
  // current when one run over the whole range assembles the sheet and video.
  for (int frame : config_.frames)
    keys_.push_back(hash_hex(concat(base, "\n", frame, "\n", file_stamp(shot_.target_path(frame)))));
}

// The temporal guide and the warm start need the motion guides of every
// frame that follows its predecessor (the light-path guides are checked by
// the shot).
void StylizeJob::check_temporal_guides() const {
  if (config_.stylit.temporal_weight <= 0 && !warm_starts(config_.stylit)) return;
  const char* what = config_.stylit.temporal_weight > 0 ? "the temporal guide" : "the warm start";
  for (std::size_t i = 0; i < config_.frames.size(); ++i)
    if (!shot_.has_motion(i) && has_temporal_predecessor(i))
      throw ValueError(concat(what, " needs velocity_backward and occlusion_backward, missing from '",
                              shot_.target_path(config_.frames[i]), "'"));
}

std::string StylizeJob::report_path() const { return report_.path(); }

std::string StylizeJob::field_folder() const { return (fs::path(config_.out) / kFieldFolder).string(); }

std::string StylizeJob::field_path(int frame) const {
  return (fs::path(field_folder()) / frame_file("field_", frame, "exr")).string();
}

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
    // A warm start's next frame reads this frame's matches: without them it is made again.
    const auto done = report_.current(result.frame, keys_[index], result.path, warnings_);
    if (done && (!warm_starts(config_.stylit) || fs::is_regular_file(field_path(result.frame), ec))) {
      result.status = "skipped";
      result.flicker = done->flicker;
      result.source_coverage = done->source_coverage;
      return result;
    }
  }
  std::vector<std::string> names = shot_.guides();
  if (shot_.has_motion(index)) names.insert(names.end(), {"velocity_backward", "occlusion_backward"});
  const GuideFrame target = GuideFrame::read(shot_.target_path(result.frame), names);

  // The predecessor (and its matches) as written to disk, whether made now
  // or in an earlier run: a resumed sequence then continues exactly like an
  // uninterrupted one.
  Image previous;
  OffsetField previous_field;
  const bool chained = has_temporal_predecessor(index) && shot_.has_motion(index);
  if (chained) {  // the temporal guide's, and the flicker figure's
    const std::string path = output_path(config_.frames[index - 1]);
    if (fs::is_regular_file(path, ec)) previous = read_image(path);
  }
  if (chained && warm_starts(config_.stylit)) {
    const std::string path = field_path(config_.frames[index - 1]);
    if (fs::is_regular_file(path, ec)) previous_field = field_from_positions(read_image(path).view());
  }
  TemporalInput temporal;
  const bool has_temporal = !previous.empty() || !previous_field.x.empty();
  if (has_temporal) {
    temporal.previous = previous.view();
    temporal.velocity_backward = target.get("velocity_backward").view();
    temporal.occlusion_backward = target.get("occlusion_backward").view();
    if (!previous_field.x.empty()) temporal.previous_field = &previous_field;
  }

  SynthesisResult synth = stylize_frame(shot_.style().view(), shot_.exemplar(), target,
                                        has_temporal ? &temporal : nullptr, config_.stylit, progress);
  if (warm_starts(config_.stylit)) {  // before the frame: a frame on disk always has its matches
    create_output_folder(field_folder());
    write_image(field_path(result.frame), field_positions(synth.field).view());
  }
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

}  // namespace tempera

#include "tempera/methods/rigid/rigid_job.hpp"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdint>
#include <map>
#include <filesystem>

#include "tempera/app/contact_sheet.hpp"
#include "tempera/app/file_keys.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/app/paths.hpp"
#include "tempera/app/record.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/methods/rigid/rigid_exemplar.hpp"
#include "tempera/methods/rigid/rigid_frame.hpp"
#include "tempera/methods/rigid/stroke_resynthesis.hpp"

namespace fs = std::filesystem;

namespace tempera {
namespace {

constexpr const char* kRecordFormat = "tempera-rigid-frame 1";
constexpr const char* kRecordsFolder = "tempera_rigid";
constexpr float kPaper[3] = {0.97f, 0.96f, 0.92f};
// The generated exemplar's canvas: its floor (y = 330) and throw fit in it.
constexpr int kGeneratedWidth = 640, kGeneratedHeight = 360;

std::string names_of(const TracksFile& tracks) {
  std::string out;
  for (const auto& [name, track] : tracks.objects) out += concat(out.empty() ? "" : ", ", name);
  return out.empty() ? "none" : out;
}

// The object `name` of `tracks` (its only one when `name` is empty).
const std::string& one_object(const TracksFile& tracks, const std::string& name, const std::string& where) {
  if (name.empty()) {
    if (tracks.objects.size() != 1)
      throw ValueError(concat(where, " tracks ", tracks.objects.size(), " objects (", names_of(tracks),
                              "): name one with --object"));
    return tracks.objects.begin()->first;
  }
  const auto found = tracks.objects.find(name);
  if (found == tracks.objects.end())
    throw ValueError(concat(where, " has no object '", name, "' (it has ", names_of(tracks), ")"));
  return found->first;
}

std::string drawn_path(const std::string& folder, int frame) {
  return (fs::path(folder) / "drawn" / frame_file("", frame, "png")).string();
}

std::string names_text(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += concat(n.size(), ":", n, ";");  // any name, unambiguous
  return out;
}

int shape_symmetry(ProxyShape shape) { return shape == ProxyShape::box ? 4 : 0; }

// Straight-alpha `layer` over straight-alpha `below`, in place.
void lay_over(Image& below, const Image& layer) {
  for (std::size_t i = 0; i < below.pixel_count(); ++i) {
    float* b = below.data() + 4 * i;
    const float* l = layer.data() + 4 * i;
    const float a = l[3], under = b[3] * (1.0f - a), alpha = a + under;
    for (int c = 0; c < 3; ++c) b[c] = (l[c] * a + b[c] * under) / std::max(alpha, 1e-6f);
    b[3] = alpha;
  }
}

// Straight-alpha RGBA made opaque over the paper colour.
void lay_on_paper(Image& rgba) {
  for (std::size_t i = 0; i < rgba.pixel_count(); ++i) {
    float* p = rgba.data() + 4 * i;
    const float a = p[3];
    for (int c = 0; c < 3; ++c) p[c] = p[c] * a + kPaper[c] * (1.0f - a);
    p[3] = 1.0f;
  }
}

}  // namespace

RigidExemplarFiles read_rigid_exemplar_files(const std::string& folder) {
  const TracksFile tracks = read_tracks_file(folder);
  RigidExemplarFiles files{tracks.objects.at(one_object(tracks, "", concat("exemplar ", folder))), {}};
  for (int i = 0; i < int(files.track.frames.size()); ++i) {
    files.drawings.push_back(drawn_path(folder, tracks.frame_start + i));
    std::error_code ec;
    if (!fs::is_regular_file(files.drawings.back(), ec))
      throw FileNotFoundError(
          concat(files.drawings.back(), ": drawn frame missing (every frame of the exemplar must be drawn)"));
  }
  return files;
}

std::vector<std::string> rigid_exemplar_folders(const std::string& examples) {
  std::error_code ec;
  if (!fs::is_directory(examples, ec))
    throw FileNotFoundError(concat("the rigid-body exemplar folder '", examples, "' does not exist"));
  if (fs::is_regular_file(fs::path(examples) / kTracksName, ec)) return {examples};
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator(examples, ec))
    if (entry.is_directory() && fs::is_regular_file(entry.path() / kTracksName, ec)) found.push_back(entry.path().string());
  std::sort(found.begin(), found.end());
  if (found.empty())
    throw ValueError(concat("'", examples, "' holds no exemplar: an exemplar is a folder with the source simulation's ",
                            kTracksName, " and its drawn frames drawn/NNNN.png"));
  return found;
}

void write_generated_rigid_exemplar(const std::string& folder, const std::string& shape) {
  std::error_code ec;
  if (fs::is_regular_file(fs::path(folder) / kTracksName, ec)) return;
  ExemplarStyle style;
  style.shape = parse_enum<ProxyShape>(shape, "proxy shape");
  const Track track = bouncing_ball({60, 60}, {5.0, 0}, 20, 1.0, 330, 0.65, style.shape == ProxyShape::box ? 0.12 : 0.05, 60);
  create_output_folder((fs::path(folder) / "drawn").string());
  for (int f = 0; f < int(track.frames.size()); ++f)
    write_image(drawn_path(folder, 1 + f), draw_exemplar_frame(track, f, style, kGeneratedWidth, kGeneratedHeight).view());
  TracksFile tracks;
  tracks.frame_start = 1;
  tracks.gravity = {0, 1.0};
  tracks.objects["Generated"] = track;
  write_tracks_file(folder, tracks);
}

struct RigidJob::Solved {
  std::vector<RigidExemplar> exemplars;
  std::vector<std::vector<Image>> residuals;  // per exemplar and frame
  struct Target {
    std::vector<RigidFrame> deformations;  // per tracked frame
    std::vector<Vec2> shifts;
  };
  std::map<std::string, Target> targets;

  ImageView residual(int e, int f) const { return residuals[std::size_t(e)][std::size_t(f)].view(); }
};

RigidJob::~RigidJob() = default;

RigidJob::RigidJob(RigidJobConfig config) : config_(std::move(config)) {
  check_job_config(config_);
  const ProxyShape shape = parse_enum<ProxyShape>(config_.shape, "proxy shape");
  if (!config_.symmetry_given) config_.options.symmetry = shape_symmetry(shape);
  validate_fields(config_.options, rigid_option_table());
  validate_fields(config_.fit, quadratic_fit_option_table());
  tracks_ = read_tracks_file(config_.guides);
  select_objects();
  std::tie(width_, height_) = guide_cache_frame_size(config_.guides);
  check_frames();
  const std::string exemplar_stamps = take_exemplars();
  take_strokes();
  list_inputs();
  settings_ = concat(kRecordFormat, ";", settings_text(config_.options, rigid_option_table()),
                     settings_text(config_.fit, quadratic_fit_option_table()), "shape=", config_.shape,
                     ";paper=", config_.paper, ";objects=", names_text(objects_), ";strokes=",
                     config_.strokes.empty() || config_.strokes == kGeneratedStrokes ? config_.strokes
                                                                                       : file_stamp(config_.strokes),
                     ";size=", width_, "x", height_, ";format=", config_.format, ";",
                     file_stamp((fs::path(config_.guides) / kTracksName).string()), ";", exemplar_stamps);
}

// The targets: config.objects (each tracked), or every tracked object; sorted.
void RigidJob::select_objects() {
  if (tracks_.objects.empty()) throw ValueError(concat("guide cache ", config_.guides, " tracks no object"));
  for (const std::string& name : config_.objects) objects_.push_back(one_object(tracks_, name, concat("guide cache ", config_.guides)));
  if (objects_.empty())
    for (const auto& [name, track] : tracks_.objects) objects_.push_back(name);
  std::sort(objects_.begin(), objects_.end());
  objects_.erase(std::unique(objects_.begin(), objects_.end()), objects_.end());
}

// Every frame asked for must be tracked for every target.
void RigidJob::check_frames() const {
  std::size_t tracked = SIZE_MAX;
  for (const std::string& name : objects_) tracked = std::min(tracked, tracks_.objects.at(name).frames.size());
  const int first = tracks_.frame_start, last = first + int(tracked) - 1;
  for (int f : config_.frames)
    if (f < first || f > last)
      throw ValueError(concat("frame ", f, " is outside the tracked frames ", first, "-", last));
}

// The exemplar folders, and their files read and checked (the generated
// exemplar's once written, by solved()); returns their part of the settings.
std::string RigidJob::take_exemplars() {
  if (config_.exemplar == kGeneratedRigidExemplar) {
    // Beside the frames folder (OUT/frames: make_method_job), in OUT.
    const fs::path out = fs::path(config_.out).parent_path();
    exemplar_folders_ = {(out / concat("exemplar_generated_", config_.shape)).string()};
    return concat("generated ", config_.shape);  // made the same every time
  }
  exemplar_folders_ = rigid_exemplar_folders(config_.exemplar);
  std::string stamps;
  for (const std::string& folder : exemplar_folders_) {
    exemplar_files_.push_back(read_rigid_exemplar_files(folder));
    stamps += file_stamp((fs::path(folder) / kTracksName).string()) + ";";
    for (const std::string& drawing : exemplar_files_.back().drawings) stamps += file_stamp(drawing) + ";";
  }
  return stamps;
}

void RigidJob::take_strokes() {
  if (!config_.strokes.empty()) strokes_ = load_stroke_exemplar(config_.strokes);
}

// What the job reads, which no output of it may replace (app/job_inputs.hpp).
void RigidJob::list_inputs() {
  if (config_.exemplar != kGeneratedRigidExemplar) inputs_.add_folder(config_.exemplar, "exemplar", "the drawn exemplar");
  for (std::size_t e = 0; e < exemplar_files_.size(); ++e) {
    inputs_.add_folder(exemplar_folders_[e], "exemplar", "the drawn exemplar");
    inputs_.add_file((fs::path(exemplar_folders_[e]) / kTracksName).string(), "exemplar tracks");
    for (const std::string& drawing : exemplar_files_[e].drawings) inputs_.add_file(drawing, "drawn exemplar frame");
  }
  if (!config_.strokes.empty() && config_.strokes != kGeneratedStrokes) inputs_.add_file(config_.strokes, "stroke exemplar");
  inputs_.add_folder(config_.guides, "guide cache", "the guides");
  inputs_.add_file((fs::path(config_.guides) / kTracksName).string(), "target tracks");
  inputs_.add_file((fs::path(config_.guides) / "manifest.json").string(), "manifest");
  inputs_.refuse_folder(config_.out);
  for (int f : config_.frames)
    for (const std::string& path : {output_path(f), record_path(f)}) inputs_.refuse_file(path);
}

std::string RigidJob::output_path(int frame) const {
  return (fs::path(config_.out) / frame_file("frame_", frame, config_.format)).string();
}

std::string RigidJob::record_path(int frame) const {
  return (fs::path(config_.out) / kRecordsFolder / frame_file("frame_", frame, "txt")).string();
}

std::string RigidJob::frame_key(int frame) const { return hash_hex(concat(settings_, "\nframe ", frame)); }

// The exemplars fitted (D per drawn frame, and the residuals) and every
// tracked frame's deformation and contact fix: a frame needs them all
// (sub-sequences span events), so they are made once, by the first frame made.
// The fit is most of that frame's time (tens of seconds for the generated
// exemplar): `progress` hears of each drawing fitted and may cancel.
const RigidJob::Solved& RigidJob::solved(const ProgressCallback& progress) {
  if (solved_) return *solved_;
  auto s = std::make_unique<Solved>();
  if (exemplar_files_.empty()) {  // the generated exemplar
    write_generated_rigid_exemplar(exemplar_folders_[0], config_.shape);
    exemplar_files_.push_back(read_rigid_exemplar_files(exemplar_folders_[0]));
  }
  const ProxyShape shape = parse_enum<ProxyShape>(config_.shape, "proxy shape");
  std::size_t drawings = 0, fitted = 0;
  for (const RigidExemplarFiles& files : exemplar_files_) drawings += files.drawings.size();
  for (const RigidExemplarFiles& files : exemplar_files_) {
    RigidExemplar e{files.track, {}};
    std::vector<Image> residuals;
    for (std::size_t f = 0; f < files.drawings.size(); ++f) {
      const Image drawing = read_image(files.drawings[f]);
      if (drawing.channels() != 4) throw ValueError(concat(files.drawings[f], ": a drawn frame must be RGBA (ink in alpha)"));
      const TrackFrame& t = files.track.frames[f];
      const ObjectFrame object{t.centre, t.radius};
      const Image mask = proxy_mask(t, shape, drawing.width(), drawing.height());
      const Image ink = extract_channels(drawing.view(), 3, 1);
      e.maps.push_back(fit_quadratic_map(mask.view(), ink.view(), object, config_.fit));
      residuals.push_back(extract_residual(drawing.view(), e.maps.back(), object));
      if (progress && !progress(0.9 * double(++fitted) / double(drawings)))
        throw CancelledError("rigid-body stylization cancelled");
    }
    s->exemplars.push_back(std::move(e));
    s->residuals.push_back(std::move(residuals));
  }
  const Solved& view = *s;
  const ResidualSource source = [&view](int e, int f) { return view.residual(e, f); };
  for (const std::string& name : objects_) {
    const Track& target = tracks_.objects.at(name);
    Solved::Target& t = s->targets[name];
    t.deformations = synthesize_deformations(s->exemplars, target, config_.options);
    t.shifts = contact_shifts(s->exemplars, source, target, t.deformations, width_, height_, config_.options.contact_fade);
  }
  solved_ = std::move(s);
  return *solved_;
}

FrameResult RigidJob::run_frame(std::size_t index, const ProgressCallback& progress) {
  const int f = config_.frames.at(index);
  FrameResult result;
  result.frame = f;
  result.path = output_path(f);
  result.status = "skipped";
  if (config_.resume && record_current(record_path(f), kRecordFormat, frame_key(f), {result.path})) return result;
  const auto t0 = std::chrono::steady_clock::now();
  if (progress && !progress(0.0)) throw CancelledError("rigid-body stylization cancelled");
  solved(progress);
  Image rgba;
  if (objects_.size() == 1) {
    rgba = draw_object(objects_[0], f, progress);
    if (config_.paper) lay_on_paper(rgba);
  } else {
    rgba = Image(width_, height_, 4);
    if (config_.paper) lay_on_paper(rgba);
    for (const std::string& name : far_to_near(f)) lay_over(rgba, draw_object(name, f, progress));
  }
  create_output_folder((fs::path(config_.out) / kRecordsFolder).string());
  write_image(result.path, rgba.view());
  write_record(record_path(f), kRecordFormat, frame_key(f), {result.path});
  result.status = "stylized";
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

// The targets far to near at `frame` (the tracks' camera depth; an object
// without one counts as depth 0, and ties keep the name order).
std::vector<std::string> RigidJob::far_to_near(int frame) const {
  const std::size_t i = std::size_t(frame - tracks_.frame_start);
  const auto key = [&](const std::string& name) {
    const auto depth = tracks_.depths.find(name);
    return depth == tracks_.depths.end() ? 0.0 : -depth->second[i];
  };
  std::vector<std::string> order = objects_;
  std::stable_sort(order.begin(), order.end(), [&](const auto& a, const auto& b) { return key(a) < key(b); });
  return order;
}

// One object's drawing at `frame` (RGBA, straight alpha), its lines re-drawn
// from the stroke exemplar when there is one.
Image RigidJob::draw_object(const std::string& name, int frame, const ProgressCallback& progress) const {
  const Solved& s = *solved_;
  const Solved::Target& t = s.targets.at(name);
  const std::size_t i = std::size_t(frame - tracks_.frame_start);
  const ResidualSource source = [&s](int e, int k) { return s.residual(e, k); };
  Image rgba = render_rigid_frame(s.exemplars, source, tracks_.objects.at(name), int(i), t.deformations[i], width_,
                                  height_, t.shifts[i]);
  if (strokes_.empty()) return rgba;
  return resynthesize_strokes(rgba.view(), strokes_.view(), config_.options.stroke_d_max,
                              config_.options.stroke_weight, 1, progress);
}

void RigidJob::write_contact_sheet(const std::string& path, int columns) const {
  inputs_.refuse_file(path);
  std::vector<std::string> files;
  std::error_code ec;
  for (int frame : config_.frames)
    if (fs::is_regular_file(output_path(frame), ec)) files.push_back(output_path(frame));
  const RigidExemplarFiles first =
      exemplar_files_.empty() ? read_rigid_exemplar_files(exemplar_folders_.front()) : exemplar_files_.front();
  const Image drawing = read_image(first.drawings[first.drawings.size() / 2]);
  write_frames_contact_sheet(path, drawing.view(), files, columns);
}

}  // namespace tempera

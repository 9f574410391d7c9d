#include "tempera/methods/tcia/tcia_job.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tempera/engine/distance_transform.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/app/file_keys.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/engine/orientation.hpp"
#include "tempera/app/paths.hpp"
#include "tempera/app/record.hpp"
#include "tempera/app/text_file.hpp"

namespace fs = std::filesystem;

namespace tempera {
namespace {

const char* const kMotion[] = {"velocity_backward", "occlusion_backward", "velocity_forward", "occlusion_forward"};

// The frames of the shot's keys and of the layers' own: the segments' bounds.
std::vector<int> key_frames(const TciaJobConfig& c) {
  std::vector<int> frames;
  for (const KeyFile& k : c.keys) frames.push_back(k.frame);
  for (const LayerFile& l : c.layers)
    for (const KeyFile& k : l.keys) frames.push_back(k.frame);
  return frames;
}

std::vector<KeyFile> sorted_keys(std::vector<KeyFile> keys, const std::vector<int>& frames) {
  std::sort(keys.begin(), keys.end(), [](const KeyFile& a, const KeyFile& b) { return a.frame < b.frame; });
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const KeyFile& k = keys[i];
    if (i > 0 && keys[i - 1].frame == k.frame) throw ValueError(concat("keyframe ", k.frame, " is given twice"));
    if (k.frame < frames.front() || k.frame > frames.back())
      throw ValueError(concat("keyframe ", k.frame, " is outside the frames ", frames.front(), "-", frames.back()));
    for (const std::string* path : {&k.painting, &k.mask}) {
      std::error_code ec;
      if (!path->empty() && !fs::is_regular_file(*path, ec))
        throw FileNotFoundError(concat(path == &k.painting ? "painting" : "mask", " of keyframe ", k.frame,
                                       " not found: '", *path, "'"));
    }
  }
  return keys;
}

// A key painting with the style's channels (an RGBA PNG of an RGB style
// drops its alpha), at its frame's size.
Image read_key_painting(const KeyFile& k, int channels, int width, int height) {
  Image p = read_image(k.painting);
  require_finite(p.view(), concat("the painting of keyframe ", k.frame));
  if (p.channels() < channels)
    throw ValueError(concat("the painting of keyframe ", k.frame, " '", k.painting, "' has ", p.channels(),
                            " channel(s), the style ", channels));
  if (p.width() != width || p.height() != height)
    throw ValueError(concat("the painting of keyframe ", k.frame, " '", k.painting, "' is ", p.width(), "x",
                            p.height(), " but frame ", k.frame, "'s guides are ", width, "x", height));
  return p.channels() == channels ? p : extract_channels(p.view(), 0, channels);
}

Image read_key_mask(const KeyFile& k, int width, int height) {
  if (k.mask.empty()) return {};
  Image m = read_image(k.mask);
  if (m.width() != width || m.height() != height)
    throw ValueError(concat("the mask of keyframe ", k.frame, " '", k.mask, "' is ", m.width(), "x", m.height(),
                            " but frame ", k.frame, "'s guides are ", width, "x", height));
  Image out = extract_channels(m.view(), 0, 1);
  for (std::size_t i = 0; i < out.pixel_count(); ++i) out.data()[i] = out.data()[i] > 0.5f ? 1.0f : 0.0f;
  return out;
}

bool has_guide(const ImageFileInfo& info, const std::string& guide) {
  return std::any_of(info.channel_names.begin(), info.channel_names.end(),
                     [&](const std::string& c) { return c.rfind(guide + ".", 0) == 0; });
}

// O(I) of a guide frame: the angle of its structure tensor (orientation.hpp).
Image tensor_angle(const GuideFrame& g) {
  return extract_channels(orientation_from_tensor(g.get("tensor").view()).view(), 0, 1);
}

// D(S): the bounded distance to the painting's ink (eq. 9).
Image ink_distance(const ImageView& style, const TciaLineOptions& o) {
  Image ink(style.width, style.height, 1);
  for (int y = 0; y < style.height; ++y)
    for (int x = 0; x < style.width; ++x) {
      const float* p = style.pixel(x, y);
      const float lum = style.channels >= 3 ? 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2] : p[0];
      ink.at(x, y, 0) = lum < o.ink ? 1.0f : 0.0f;
    }
  return line_distance(ink.view(), o.d_max);
}

}  // namespace

// The painting, the exemplar's guides and the frames to solve (a farm task's
// segment only), read and checked; the output folder made.
LightPathShot checked_shot(const TciaJobConfig& c, std::vector<std::string>& warnings) {
  LightPathShotConfig shot = c;
  if (c.segment) {
    shot.frames.clear();
    for (int f = c.segment->first; f <= c.segment->second; ++f) shot.frames.push_back(f);
  }
  LightPathShot out(shot, active_guide_names(c.weights), warnings);
  out.prepare_output();
  return out;
}

KeyFile parse_key(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw ValueError(concat("--key expects FRAME=PAINTING[,MASK], got '", text, "'"));
  KeyFile k;
  k.frame = parse_number<int>(text.substr(0, eq), concat("the frame of --key '", text, "'"));
  const std::string files = text.substr(eq + 1);
  const std::size_t comma = files.find(',');
  k.painting = files.substr(0, comma);
  if (comma != std::string::npos) k.mask = files.substr(comma + 1);
  if (k.painting.empty() || (comma != std::string::npos && k.mask.empty()))
    throw ValueError(concat("--key expects FRAME=PAINTING[,MASK], got '", text, "'"));
  return k;
}

// Options, keys and segments are checked before the shot's files are read.
TciaJob::TciaJob(TciaJobConfig config)
    : config_(checked(std::move(config))),
      segments_(key_segments(config_.frames, key_frames(config_))),
      selected_(select_segments(segments_, config_.segment)),
      shot_(checked_shot(config_, warnings_)) {
  // Motion: a segment's frames link to their neighbours inside it; its first
  // frame needs no V-, its last no V+.
  for (std::size_t i : selected_) {
    const Segment& s = segments_[i];
    for (int f = s.first; f <= s.last; ++f) {
      const std::string path = shot_.target_path(f);
      const ImageFileInfo info = inspect_image(path);
      if (config_.lines.weight > 0 && !has_guide(info, "line_distance"))
        throw ValueError(concat("the line term (--lines) needs 'line_distance' in '", path, "'"));
      if (config_.orientation.from_cache && !has_guide(info, "tensor"))
        throw ValueError(concat("--orientation needs the structure tensor 'tensor' in '", path, "'"));
      for (int m = f == s.first ? 2 : 0; m < (f == s.last ? 2 : 4); ++m)
        if (!has_guide(info, kMotion[m]))
          throw ValueError(concat("the coherent method needs '", kMotion[m], "' in '", path,
                                  "' (render the guides with motion)"));
    }
  }
  if (config_.orientation.from_cache && !has_guide(inspect_image(shot_.exemplar_path()), "tensor"))
    throw ValueError(concat("--orientation needs the structure tensor 'tensor' in the exemplar's guides '",
                            shot_.exemplar_path(), "'"));
  refuse_writing_on_keys();
  read_keys(config_.keys, paintings_, masks_);
  for (const LayerFile& l : config_.layers)
    read_keys(l.keys, layer_key_paintings_.emplace_back(), layer_key_masks_.emplace_back());
  std::ostringstream s;
  s << kTciaRecordFormat << ";weights=";
  for (const auto& [name, weight] : active_guides(config_.weights)) s << name << ":" << weight << ",";
  s << ";" << settings_text(config_.tcia, tcia_option_table())
    << settings_text(config_.tcia.synthesis, synthesis_option_table())
    << settings_text(config_.lines, tcia_line_option_table())
    << settings_text(config_.orientation, tcia_orientation_option_table()) << "format=" << config_.format << ";"
    << file_stamp(config_.exemplar) << ";" << file_stamp(shot_.exemplar_path());
  settings_ = s.str();
  check_layers();
  std::error_code ec;
  fs::create_directories(fs::path(config_.out) / "tempera_tcia", ec);
}

TciaJobConfig TciaJob::checked(TciaJobConfig c) {
  check_job_config(c, FrameOrder::Consecutive,
                   "the coherent method needs consecutive frames (the motion links frame f to f - 1 and f + 1)");
  validate_fields(c.tcia, tcia_option_table());
  validate_fields(c.lines, tcia_line_option_table());
  validate_fields(c.orientation, tcia_orientation_option_table());
  validate(c.tcia.synthesis);
  if (c.layer_order != "depth" && c.layer_order != "given")
    throw ValueError(concat("the layer order must be 'depth' or 'given', got '", c.layer_order, "'"));
  c.keys = sorted_keys(std::move(c.keys), c.frames);
  for (LayerFile& l : c.layers) l.keys = sorted_keys(std::move(l.keys), c.frames);
  return c;
}

// The shot refuses writing onto the guides and the painting; the
// key paintings, their masks and the layers' paintings may sit in the output
// folder too (a painted frame_0004.png): refuse before anything is written.
void TciaJob::refuse_writing_on_keys() const {
  JobInputs inputs;
  const auto add_keys = [&](const std::vector<KeyFile>& keys) {
    for (const KeyFile& k : keys) {
      inputs.add_file(k.painting, concat("painting of keyframe ", k.frame));
      inputs.add_file(k.mask, concat("mask of keyframe ", k.frame));
    }
  };
  add_keys(config_.keys);
  for (const LayerFile& l : config_.layers) {
    add_keys(l.keys);
    inputs.add_file(l.painting, concat("painting of layer '", l.name, "'"));
  }
  for (const Segment& s : segments_)
    for (int f : s.writes) {
      inputs.refuse_file(shot_.output_path(f));
      for (std::size_t l = 0; l < config_.layers.size(); ++l) inputs.refuse_file(layer_path(l, f));
    }
}

void TciaJob::read_keys(const std::vector<KeyFile>& keys, std::vector<Image>& paintings,
                        std::vector<Image>& masks) const {
  for (const KeyFile& k : keys) {
    paintings.emplace_back(), masks.emplace_back();
    if (!is_read(k.frame)) continue;  // outside the one segment run
    const ImageFileInfo info = inspect_image(shot_.target_path(k.frame));
    paintings.back() = read_key_painting(k, shot_.style().channels(), info.width, info.height);
    masks.back() = read_key_mask(k, info.width, info.height);
  }
}

bool TciaJob::is_read(int frame) const {
  return !config_.segment || (frame >= config_.segment->first && frame <= config_.segment->second);
}

std::string TciaJob::record_path(std::size_t index) const {
  const Segment& s = segments_.at(index);
  return (fs::path(config_.out) / "tempera_tcia" / concat("segment_", s.first, "-", s.last, ".txt")).string();
}

// Everything the segment's frames depend on: the settings, the painting and
// exemplar, its own guide frames and its bounding keys; nothing of the
// other segments.
std::string TciaJob::segment_key(const Segment& segment) const {
  std::string text = concat(settings_, "\nsegment ", segment.first, "-", segment.last);
  for (int f = segment.first; f <= segment.last; ++f) text += "\n" + file_stamp(shot_.target_path(f));
  for (const KeyFile& k : config_.keys)
    if (k.frame == segment.first || k.frame == segment.last)
      text += concat("\nkey ", k.frame, " ", file_stamp(k.painting), " ", k.mask.empty() ? "" : file_stamp(k.mask));
  return hash_hex(text);
}

std::string TciaJob::composite_key(const Segment& segment) const {
  if (config_.layers.empty()) return segment_key(segment);
  std::string text = concat(segment_key(segment), "\nlayer order ", config_.layer_order);
  for (std::size_t l = 0; l < config_.layers.size(); ++l) text += "\n" + layer_key(segment, l);
  return hash_hex(text);
}

bool TciaJob::is_current(std::size_t index) const {
  std::vector<std::string> files;
  for (int f : segments_[index].writes) files.push_back(shot_.output_path(f));
  return record_current(record_path(index), kTciaRecordFormat, composite_key(segments_[index]), files);
}

Shot TciaJob::load_shot(const Segment& segment, std::deque<Image>& keep, ScratchImages& frame_inputs) const {
  const std::vector<std::string>& names = shot_.guides();
  Shot shot;
  shot.style = shot_.style().view();
  for (const auto& [name, weight] : active_guides(config_.weights)) {
    shot.guide_names.push_back(name);
    shot.style_guides.push_back(keep.emplace_back(tonemap_guide(shot_.exemplar().get(name).view())).view());
    shot.guide_weights.push_back(weight);
  }
  const bool lines = config_.lines.weight > 0;
  if (lines) {
    shot.guide_names.push_back("line_distance");
    shot.style_guides.push_back(keep.emplace_back(ink_distance(shot_.style().view(), config_.lines)).view());
    shot.guide_weights.push_back(config_.lines.weight);
  }
  const bool oriented = config_.orientation.from_cache;
  if (oriented)
    shot.style_orientation = keep.emplace_back(tensor_angle(GuideFrame::read(shot_.exemplar_path(), {"tensor"}))).view();
  for (int f = segment.first; f <= segment.last; ++f) {
    std::vector<std::string> wanted = names;
    if (lines) wanted.push_back("line_distance");
    if (oriented) wanted.push_back("tensor");
    const int from = f == segment.first ? 2 : 0, to = f == segment.last ? 2 : 4;
    for (int m = from; m < to; ++m) wanted.push_back(kMotion[m]);
    const GuideFrame g = GuideFrame::read(shot_.target_path(f), wanted);
    ShotFrame frame;
    for (const auto& name : names) frame.guides.push_back(frame_inputs.add(tonemap_guide(g.get(name).view())));
    if (lines) frame.guides.push_back(frame_inputs.add(g.get("line_distance").view()));
    if (oriented) frame.orientation = frame_inputs.add(tensor_angle(g));
    const Image& first = g.get(names.front());
    ImageView* motion[] = {&frame.velocity_backward, &frame.occlusion_backward, &frame.velocity_forward,
                           &frame.occlusion_forward};
    for (int m = 0; m < 4; ++m) {
      // Unused at the segment's ends (no neighbour there): zero motion, nothing visible.
      *motion[m] = m >= from && m < to
                       ? frame_inputs.add(g.get(kMotion[m]).view())
                       : frame_inputs.add(Image(first.width(), first.height(), m % 2 == 0 ? 2 : 1, 0.0f));
    }
    shot.frames.push_back(std::move(frame));
  }
  for (std::size_t k = 0; k < config_.keys.size(); ++k) {
    const int f = config_.keys[k].frame;
    if (f != segment.first && f != segment.last) continue;
    shot.keys.push_back(ShotKey{f - segment.first, paintings_[k].view(), masks_[k].view()});
  }
  return shot;
}

SegmentResult TciaJob::run_segment(std::size_t index, const SegmentProgress& progress) {
  if (std::find(selected_.begin(), selected_.end(), index) == selected_.end())
    throw ValueError(concat("segment ", index, " is not one this job runs"));
  const Segment& segment = segments_[index];
  SegmentResult result;
  if (config_.resume && is_current(index)) {
    result.status = "skipped";
    return result;
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::deque<Image> keep;
  // Every frame's guides and motion, half of what a segment holds, in memory
  // the kernel can page out (scratch_images.hpp): a segment larger than the
  // machine's memory then runs, where it was killed.
  ScratchImages frame_inputs(config_.out);
  const Shot shot = load_shot(segment, keep, frame_inputs);
  SweepCallback sweeps;
  if (progress)
    sweeps = [&](const SweepProgress& p) {
      SweepProgress here = p;
      here.frame += segment.first;
      return progress(here);
    };
  const std::vector<Image> images =
      config_.layers.empty() ? stylize_shot_sweeps(shot, config_.tcia, sweeps) : run_layers(index, shot, sweeps);
  std::vector<std::string> files;
  for (int f : segment.writes) {
    files.push_back(shot_.output_path(f));
    write_image(files.back(), images[std::size_t(f - segment.first)].view());  // atomic
  }
  write_record(record_path(index), kTciaRecordFormat, composite_key(segment), files);
  result.status = "stylized";
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

FrameResult TciaJob::run_unit(std::size_t index, const StageProgress& progress) {
  const Segment& segment = segments_.at(index);
  SegmentProgress sweeps;
  if (progress)
    sweeps = [&](const SweepProgress& p) {  // p.frame is a frame number here
      const bool sweep_done = p.direction > 0 ? p.frame == segment.last : p.frame == segment.first;
      return progress(p.fraction, sweep_done ? concat("level ", p.levels - p.level, "/", p.levels,
                                                      p.direction > 0 ? " forward" : " backward", " sweep")
                                             : "");
    };
  const SegmentResult r = run_segment(index, sweeps);
  FrameResult unit;
  unit.frame = segment.first;
  unit.status = r.status;
  unit.seconds = r.seconds;
  return unit;
}

}  // namespace tempera

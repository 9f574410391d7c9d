#include "light_path_extras.hpp"

#include <filesystem>
#include <iostream>

#include "frame_loop.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/app/process.hpp"
#include "tempera/methods/noisy/noisy_sequence.hpp"

namespace fs = std::filesystem;

namespace tempera::cli {

LightPathExtras::LightPathExtras() : noisy(default_noisy_options()) { noisy.noise = 0; }

bool take_light_path_flag(LightPathExtras& e, const std::string& flag, ArgReader& r) {
  if (flag == "--exemplar-scene") e.exemplar_scene = r.value(flag);
  else if (flag == "--fps") e.fps = r.number<double>(flag);
  else if (flag == "--no-video") e.video = false;
  else if (flag == "--noise-map") e.noise_map = r.value(flag);
  else if (flag == "--noise-reference") e.noise_reference = r.value(flag);
  else return set_from_flag(e.noisy, noisy_option_table(), flag.substr(2), [&] { return r.value(flag); });
  return true;
}

void check_light_path_extras(const LightPathExtras& e, const JobConfig& config, bool segment) {
  validate_noisy_options(e.noisy);
  if (!e.noise() && !(e.noise_map.empty() && e.noise_reference.empty()))
    throw ValueError("--noise-map and --noise-reference need --noise F (the amount of temporal noise)");
  if (!e.noise() && e.noisy.noise_guides > 0)
    throw ValueError("--noise-guides needs --noise F (guided noise is a setting of the noise pass)");
  if (e.noise() && segment)
    throw ValueError("--noise with --segment: run the noise pass once all segments are done "
                     "(tempera stylize --noise F --noise-reference OUT/frames ...)");
  if (e.noise() && e.noise_reference.empty() && config.format != "png")
    throw ValueError("--noise boils PNG frames: use --format png (the default)");
  if (!(e.fps > 0)) throw ValueError(concat("--fps must be > 0, got ", e.fps));
  if (e.noise()) {  // the noise pass runs last: its exemplar's size is checked now, not after the frames
    const ImageFileInfo exemplar = inspect_image(config.exemplar);
    check_noisy_exemplar_size(e.noisy.noise, exemplar.width, exemplar.height, e.noisy.synthesis.patch_size);
  }
}

std::string light_path_extras_help() {
  return "  --exemplar-scene FILE   .blend of the exemplar render: its guides rendered by Blender into\n"
         "                          OUT/exemplar_guides (instead of --exemplar-guides)\n"
         "  --fps F                 frame rate of the video (default 24)\n"
         "  --no-video              do not encode OUT/stylized.mp4 (H.264 of consecutive PNG frames,\n"
         "                          needs ffmpeg on PATH)\n"
         "  --noise F               Color Me Noisy after the frames (docs/noisy.md): low-pass width f in\n"
         "                          pixels, the frames boil by this amount into OUT/noisy/ (1.3 calm ..\n"
         "                          4.3 lively; 0 = off; at most 11.4, less for a small exemplar)\n"
         "  --noise-map FILE|GUIDE  where the noise goes: an image of the frames' size, or a guide of the\n"
         "                          guide cache (alpha, mask.OB_Name, an AOV); 0 = coherent, 1 = --noise\n"
         "  --noise-reference DIR   boil these coherent frames (DIR/frame_0001.png ...) instead of\n"
         "                          stylizing: no exemplar guides needed\n"
         "  (Color Me Noisy's options of 'tempera noisy --help', e.g. --consistency 2 --deform false)\n";
}

std::string render_exemplar_scene(const LightPathExtras& e, const GuideRender& how, const std::string& out,
                                  int frame) {
  const std::string folder = (fs::path(out) / "exemplar_guides").string();
  render_scene_guides(how, e.exemplar_scene, std::to_string(frame), folder);
  return folder;
}

bool consecutive(const std::vector<int>& frames) {
  for (std::size_t i = 1; i < frames.size(); ++i)
    if (frames[i] != frames[i - 1] + 1) return false;
  return true;
}

namespace {

// `video` from the PNG frames of `folder`: true if encoded, false if
// ffmpeg is not on PATH, nothing if it could not be written (a warning said so).
std::optional<bool> encode(const JobInputs& inputs, const std::string& folder, int first, double fps,
                           const fs::path& video, const std::string& what) {
  inputs.refuse_file(video.string());
  // ffmpeg reads '%' in the folder as a pattern of its own: doubled, it is a plain '%'.
  const std::string pattern = printf_escaped(folder) + "/frame_%04d.png";
  bool encoded = false;
  if (!write_beside_frames("stylize", what, [&] { encoded = encode_video(pattern, first, fps, video.string()); }))
    return std::nullopt;
  return encoded;
}

}  // namespace

void write_video(const LightPathExtras& e, const JobInputs& inputs, const JobConfig& config) {
  if (!e.video) return;
  if (config.format != "png" || !consecutive(config.frames)) {
    std::cout << "no video: it needs consecutive PNG frames\n";
    return;
  }
  const fs::path video = fs::path(config.out) / "stylized.mp4";
  const auto encoded =
      encode(inputs, (fs::path(config.out) / "frames").string(), config.frames.front(), e.fps, video, "the video");
  if (encoded) std::cout << (*encoded ? "video: " + video.string() : std::string("no video: ffmpeg is not on PATH")) << "\n";
}

bool run_noise_pass(const LightPathExtras& e, const NoisePassInputs& in) {
  const std::string out = in.config.out;
  NoisySequenceConfig c;
  c.exemplar = in.config.exemplar;
  c.reference = e.noise_reference.empty() ? (fs::path(out) / "frames").string() : e.noise_reference;
  c.frames = in.config.frames;
  c.out = (fs::path(out) / "noisy").string();
  c.noise_map = e.noise_map;
  c.guides = in.config.guides;
  c.exemplar_guides = in.exemplar_guides;  // for guided noise
  c.exemplar_frame = in.exemplar_frame;
  c.guide_weights = in.weights;
  c.options = e.noisy;
  c.options.synthesis.seed = in.synthesis.seed;
  c.options.synthesis.threads = in.synthesis.threads;
  c.resume = in.config.resume;
  NoisySequence sequence(c);
  FrameLine line;
  line.label = "noisy frame";
  std::vector<FrameResult> results;
  if (!run_frames(sequence, results, line)) return false;
  std::cout << "noisy frames: " << c.out << "\n";
  if (e.video && consecutive(c.frames) &&
      encode(sequence.inputs(), c.out, c.frames.front(), e.fps, fs::path(out) / "noisy.mp4",
             "the video of the noisy frames")
          .value_or(false))
    std::cout << "video: " << (fs::path(out) / "noisy.mp4").string() << "\n";
  return true;
}

}  // namespace tempera::cli

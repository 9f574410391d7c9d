// `tempera stylize`: a whole shot in one command. Renders the guides through
// background Blender when given .blend files (or takes existing guide caches,
// as a render farm does), runs the StylizeJob frame by frame with resume, and
// writes a contact sheet and a video.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>

#include "cli_args.hpp"
#include "frame_loop.hpp"
#include "scene_guides.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/methods/noisy/noisy_sequence.hpp"
#include "tempera/methods/registry.hpp"
#include "tempera/app/process.hpp"
#include "tempera/methods/stylit/stylize_job.hpp"
#include "tempera/methods/tcia/tcia_job.hpp"

namespace fs = std::filesystem;

namespace tempera::cli {
namespace {

const char* kStylizeHelpText =
    "usage: tempera stylize SCENE.blend --exemplar STYLE.png (--exemplar-scene EXEMPLAR.blend |\n"
    "                       --exemplar-guides DIR) --frames A-B --out DIR [options]\n"
    "       tempera stylize --guides DIR --exemplar STYLE.png --exemplar-guides DIR --frames A-B\n"
    "                       --out DIR [options]\n"
    "\n"
    "Stylizes an animation with StyLit (light-path guides) from a painted exemplar.\n"
    "With SCENE.blend the scene's guides are rendered first with background Blender into\n"
    "--guides (default OUT/guides), and with --exemplar-scene the exemplar's guides into\n"
    "OUT/exemplar_guides; guide frames already current are reused. The second form needs\n"
    "no Blender: it reads existing guide caches (render farms).\n"
    "\n"
    "outputs:\n"
    "  OUT/frames/frame_0001.png ...   stylized frames (each written atomically)\n"
    "  OUT/frames/tempera_stylize.json settings, resume key and flicker per frame\n"
    "  OUT/contact_sheet.png           the painting followed by the frames\n"
    "  OUT/stylized.mp4                H.264 video (needs ffmpeg on PATH; PNG frames)\n"
    "\n"
    "inputs:\n"
    "  --exemplar FILE         the painting, made on the exemplar render (same aspect)\n"
    "  --exemplar-scene FILE   .blend of the exemplar render (guides rendered by Blender)\n"
    "  --exemplar-guides DIR   guide cache of the exemplar render\n"
    "  --exemplar-frame N      frame of the exemplar (default: 1 with --exemplar-scene,\n"
    "                          else the only frame in --exemplar-guides)\n"
    "  --guides DIR            guide cache of the animation (default OUT/guides with SCENE)\n"
    "  --frames RANGE          frames to stylize, e.g. 1-24 or 1-10,15\n"
    "  --out DIR               output folder\n"
    "\n"
    "stylization:\n"
    "  --weights LIST          light-path guide weights (default @WEIGHTS@);\n"
    "                          guides not listed keep their default, 0 leaves a guide out\n"
    "@STYLIT@"
    "  --usage MODE            none | penalty | uniform | budget (default budget)\n"
    "  --patch-size N          odd patch width (default 5)\n"
    "  --seed N                random seed (default 1)\n"
    "  --threads N             worker threads (default 0 = all cores)\n"
    "  (any engine option of 'tempera synth --help', e.g. --em-iters 4 --window-sigma 3)\n"
    "  --format F              png (default) | exr (float, linear as painted)\n"
    "  --fps F                 frame rate of the video (default 24)\n"
    "  --no-video              do not encode OUT/stylized.mp4\n"
    "  --no-resume             stylize every frame again, even if current\n"
    "\n"
    "method:\n"
    "  --method M              the method (default stylit); each has its own options\n"
    "                          (tempera stylize --method M --help):\n"
    "@METHODS@"
    "                          tcia solves the whole shot in forward and backward sweeps along\n"
    "                          the motion: consecutive frames with velocity_forward/backward and\n"
    "                          occlusion_forward/backward\n"
    "  --key F=PATH[,MASK]     tcia: a painted keyframe (repeatable); comes out as painted\n"
    "                          (where MASK > 0.5 if given) and steers its neighbours\n"
    "  --segment A-B           tcia: solve only the segment from key A to key B (a farm\n"
    "                          task); the shot splits at keys into independent segments\n"
    "  --layer NAME=MASK[,PAINTING]  tcia: a layer (repeatable), solved alone with its motion\n"
    "                          extrapolated past its outline (Benard 2013 Fig. 10): MASK is the\n"
    "                          guide cache's mask of its object or collection (mask.CO_Suit),\n"
    "                          PAINTING its own painting over the exemplar render (default: the\n"
    "                          shared one); frames RGBA in OUT/frames/layers/NAME/, composited\n"
    "                          into OUT/frames (the back-most layer fills what no mask covers)\n"
    "  --layer-key NAME:F=PATH[,MASK]  tcia: a key of layer NAME only (repeatable): at frame F it\n"
    "                          replaces the --key of that frame for the layer, so the layer's pixels\n"
    "                          of the composite come out as painted; segments split there too\n"
    "  --layer-order O         depth (default: per frame, by the guide cache's depth) | given\n"
    "                          (the --layer order, first at the back)\n"
    "@TCIA@"
    "@LINES@"
    "  tcia's engine defaults: 9x9 Gaussian window, centre output, histogram usage, automatic levels;\n"
    "  its --temporal defaults to 3. Resume, Ctrl-C and SIGTERM work per segment.\n"
    "temporal noise (Color Me Noisy, after the coherent frames; docs/noisy.md):\n"
    "  --noise F               low-pass width f in pixels: the coherent frames boil by this amount\n"
    "                          into OUT/noisy/frame_0001.png ... (1.3 calm .. 4.3 lively; 0 = off;\n"
    "                          at most 11.4, less for a small exemplar: the error says how much)\n"
    "  --noise-map FILE|GUIDE  where the noise goes: an image of the frames' size, or a guide of the\n"
    "                          guide cache (alpha, mask.OB_Name, an AOV); 0 = coherent, 1 = --noise\n"
    "  --noise-reference DIR   boil these coherent frames (DIR/frame_0001.png ...) instead of\n"
    "                          stylizing: no exemplar guides needed\n"
    "  (Color Me Noisy's options of 'tempera noisy --help', e.g. --consistency 2 --deform false)\n"
    "\n"
    "guide rendering (SCENE.blend / --exemplar-scene only):\n"
    "  --samples N             Cycles samples of the guide renders (default 16)\n"
    "  --blender PATH          Blender to run (default: $TEMPERA_BLENDER or 'blender')\n"
    "  --addon-path DIR        folder holding the tempera package\n"
    "  --max-image-pixels N    refuse images declaring more pixels (default 50000000;\n"
    "                          also $TEMPERA_MAX_IMAGE_PIXELS)\n"
    "\n"
    "Resume: a frame is skipped when its output exists and was made with the same settings,\n"
    "painting and guide files (sizes and modification times); rerun the same command after\n"
    "an interruption. Ctrl-C stops within the current frame; finished frames are kept.\n"
    "Runs sharing one --out (a render farm) each add their frames to the record under a\n"
    "lock; a damaged record is set aside with a warning and its frames are redone.\n"
    "Exit status: 0 done, 1 error (files, Blender), 2 bad usage or bad values, 130 interrupted.\n";

// One line per method of the registry: its name and title ("stylit  Per-Frame StyLit").
std::string methods_help() {
  std::string out;
  for (const MethodEntry& m : method_registry()) {
    std::string name = "                            " + m.name;
    name.resize(std::max<std::size_t>(name.size() + 1, 42), ' ');
    out += concat(name, m.title, m.python_command.empty() ? "" : " (run by the Python package's tempera)", "\n");
  }
  return out;
}

// The help, with the guide weights' defaults from the guide table and the methods from the registry.
std::string stylize_help() {
  std::string defaults;
  for (const auto& g : light_path_guides())
    defaults += (defaults.empty() ? "" : ",") + std::string(g.name) + "=" + format_value(g.weight);
  std::string text = kStylizeHelpText;
  text.replace(text.find("@WEIGHTS@"), 9, defaults);
  text.replace(text.find("@METHODS@"), 9, methods_help());
  text.replace(text.find("@STYLIT@"), 8, flags_help<StylitOptions>(stylit_option_table()));
  text.replace(text.find("@TCIA@"), 6, flags_help<TciaOptions>(tcia_option_table()));
  text.replace(text.find("@LINES@"), 7,
               flags_help<TciaLineOptions>(tcia_line_option_table()) +
                   flags_help<TciaOrientationOptions>(tcia_orientation_option_table()));
  return text;
}

NoisyOptions no_noise() {
  NoisyOptions o = default_noisy_options();
  o.noise = 0;
  return o;
}

struct Options {
  std::string scene, exemplar, exemplar_scene, exemplar_guides, guides, frames_text, out, samples;
  std::optional<int> exemplar_frame;
  std::vector<int> frames;
  StylitOptions stylit;
  NoisyOptions noisy = no_noise();  // noise 0: no noise pass
  std::string noise_map, noise_reference;
  std::string format = "png";
  double fps = 24;
  bool video = true, resume = true;
  // The coherent method: its options get the engine flags given (recorded
  // in order) on its own defaults, and --temporal if given.
  std::string method = "stylit";
  std::vector<KeyFile> keys;
  std::vector<LayerFile> layers;
  std::vector<std::pair<std::string, KeyFile>> layer_keys;  // --layer-key, added to their layers
  std::optional<std::string> layer_order;
  std::optional<std::pair<int, int>> segment;
  TciaOptions tcia = default_tcia_options();
  TciaLineOptions lines;
  TciaOrientationOptions orientation;
  std::vector<std::pair<std::string, std::string>> engine_flags;
  std::vector<std::string> tcia_flags;
  bool temporal_given = false;
  BlenderSetup blender = default_blender_setup();
};

std::pair<int, int> parse_segment(const std::string& text) {
  const std::vector<int> frames = parse_frames(text);
  if (text.find(',') != std::string::npos || frames.size() < 2)
    throw ValueError(concat("--segment expects A-B (from one key to the next), got '", text, "'"));
  return {frames.front(), frames.back()};
}

// An engine option (StyLit's, recorded for tcia) or one of tcia's own.
bool set_engine_flag(Options& o, const std::string& flag, ArgReader& r) {
  std::string text;
  auto value = [&] { return text = r.value(flag); };
  if (set_from_flag(o.stylit.synthesis, synthesis_option_table(), flag.substr(2), value)) {
    o.engine_flags.emplace_back(flag.substr(2), text);
    return true;
  }
  if (!set_from_flag(o.tcia, tcia_option_table(), flag.substr(2), value) &&
      !set_from_flag(o.lines, tcia_line_option_table(), flag.substr(2), value) &&
      !set_from_flag(o.orientation, tcia_orientation_option_table(), flag.substr(2), value))
    return false;
  o.tcia_flags.push_back(flag);
  return true;
}

// run_stylize has sent every other method to its own command.
void check_method(Options& o) {
  if (o.method == "stylit") {
    if (!o.keys.empty() || o.segment || !o.tcia_flags.empty() || !o.layers.empty() || o.layer_order)
      throw ValueError(concat(!o.keys.empty()         ? "--key"
                              : o.segment             ? "--segment"
                              : !o.layers.empty()     ? "--layer"
                              : o.layer_order         ? "--layer-order"
                                                      : o.tcia_flags.front(),
                              " needs --method tcia"));
    return;
  }
  for (const auto& [flag, text] : o.engine_flags)
    set_from_flag(o.tcia.synthesis, synthesis_option_table(), flag, [&] { return text; });
  if (o.temporal_given) o.tcia.temporal_weight = o.stylit.temporal_weight;
}

Options parse(const Args& args) {
  Options o;
  std::size_t first = 0;
  if (!args.empty() && args[0].rfind("--", 0) != 0) o.scene = args[first++];  // SCENE.blend
  const Args tail(args.begin() + first, args.end());
  ArgReader r(tail, "stylize");
  while (r.more()) {
    const std::string flag = r.flag();
    if (flag == "--exemplar") o.exemplar = r.value(flag);
    else if (flag == "--exemplar-scene") o.exemplar_scene = r.value(flag);
    else if (flag == "--exemplar-guides") o.exemplar_guides = r.value(flag);
    else if (flag == "--exemplar-frame") o.exemplar_frame = r.number<int>(flag);
    else if (flag == "--guides") o.guides = r.value(flag);
    else if (flag == "--frames") o.frames = parse_frames(o.frames_text = r.value(flag));
    else if (flag == "--out") o.out = r.value(flag);
    else if (flag == "--weights") parse_guide_weights(r.value(flag), o.stylit.weights);
    else if (set_from_flag(o.stylit, stylit_option_table(), flag.substr(2), [&] { return r.value(flag); }))
      o.temporal_given |= flag == "--temporal";  // --temporal, --quality
    else if (flag == "--format") o.format = r.value(flag);
    else if (flag == "--fps") o.fps = r.number<double>(flag);
    else if (flag == "--no-video") o.video = false;
    else if (flag == "--no-resume") o.resume = false;
    else if (flag == "--samples") o.samples = std::to_string(r.number<int>(flag));
    else if (flag == "--blender") o.blender.blender = r.value(flag);
    else if (flag == "--addon-path") o.blender.addon = r.value(flag);
    else if (flag == "--max-image-pixels") set_max_image_pixels(r.number<std::int64_t>(flag));
    else if (flag == "--method") o.method = r.value(flag);
    else if (flag == "--key") o.keys.push_back(parse_key(r.value(flag)));
    else if (flag == "--layer") o.layers.push_back(parse_layer(r.value(flag)));
    else if (flag == "--layer-key") o.layer_keys.push_back(parse_layer_key(r.value(flag)));
    else if (flag == "--layer-order") o.layer_order = r.value(flag);
    else if (flag == "--segment") o.segment = parse_segment(r.value(flag));
    else if (flag == "--noise-map") o.noise_map = r.value(flag);
    else if (flag == "--noise-reference") o.noise_reference = r.value(flag);
    else if (set_from_flag(o.noisy, noisy_option_table(), flag.substr(2), [&] { return r.value(flag); })) continue;
    else if (!set_engine_flag(o, flag, r))
      throw ValueError(concat("unknown option '", flag, "' (see tempera stylize --help)"));
  }
  add_layer_keys(o.layers, o.layer_keys);
  check_method(o);
  validate(o.stylit.synthesis);
  validate_noisy_options(o.noisy);
  const bool noise = o.noisy.noise > 0;
  if (!noise && !(o.noise_map.empty() && o.noise_reference.empty()))
    throw ValueError("--noise-map and --noise-reference need --noise F (the amount of temporal noise)");
  if (!noise && o.noisy.noise_guides > 0)
    throw ValueError("--noise-guides needs --noise F (guided noise is a setting of the noise pass)");
  if (noise && o.segment)
    throw ValueError("--noise with --segment: run the noise pass once all segments are done "
                     "(tempera stylize --noise F --noise-reference OUT/frames ...)");
  if (noise && o.noise_reference.empty() && o.format != "png")
    throw ValueError("--noise boils PNG frames: use --format png (the default)");
  if (o.exemplar.empty()) throw ValueError("--exemplar is required (the painting)");
  if (o.frames.empty()) throw ValueError("--frames is required (e.g. --frames 1-24)");
  if (o.out.empty()) throw ValueError("--out is required (the output folder)");
  if (noise) {  // the noise pass runs last: its exemplar's size is checked now, not after the coherent pass
    const ImageFileInfo exemplar = inspect_image(o.exemplar);
    check_noisy_exemplar_size(o.noisy.noise, exemplar.width, exemplar.height, o.noisy.synthesis.patch_size);
  }
  if (!o.noise_reference.empty()) {  // the coherent frames are given: no stylization
    if (o.guides.empty() && !o.scene.empty()) o.guides = (fs::path(o.out) / "guides").string();
    return o;
  }
  if (o.exemplar_scene.empty() == o.exemplar_guides.empty())
    throw ValueError("give one of --exemplar-scene EXEMPLAR.blend or --exemplar-guides DIR");
  if (o.scene.empty() && o.guides.empty())
    throw ValueError("give SCENE.blend as the first argument, or --guides DIR with an existing guide cache");
  if (!(o.fps > 0)) throw ValueError(concat("--fps must be > 0, got ", o.fps));
  if (o.guides.empty()) o.guides = (fs::path(o.out) / "guides").string();
  return o;
}

void render_guides(const Options& o, const std::string& scene, const std::string& frames, const std::string& out) {
  render_scene_guides(GuideRender{o.blender, o.samples}, scene, frames, out);
}

bool consecutive(const std::vector<int>& frames) {
  for (std::size_t i = 1; i < frames.size(); ++i)
    if (frames[i] != frames[i - 1] + 1) return false;
  return true;
}

// StyLit's frames, one line each with the flicker figure and an ETA; false if interrupted.
bool run_frames(StylizeJob& job, std::vector<FrameResult>& results) {
  FrameLine line;
  line.details = [](std::ostream& out, const FrameResult& r) {
    if (std::isfinite(r.flicker)) out << ", flicker " << std::fixed << std::setprecision(4) << r.flicker;
  };
  line.eta = true;
  return cli::run_frames(job, results, line);
}

void print_summary(const std::vector<FrameResult>& results, const std::string& out) {
  const FrameTally t = tally(results);
  int counted = 0;
  double flicker_sum = 0;
  for (const auto& r : results)
    if (std::isfinite(r.flicker)) flicker_sum += r.flicker, ++counted;
  std::cout << "tempera stylize: " << t.made << " frame(s) stylized, " << t.skipped
            << " skipped (already current) in " << std::fixed << std::setprecision(1) << t.seconds << " s";
  if (counted) std::cout << "; mean flicker " << std::setprecision(4) << flicker_sum / counted;
  std::cout << std::defaultfloat << "; results in " << out << "\n";
}

void write_extras(const LightPathShot& shot, const Options& o) {
  const fs::path sheet = fs::path(o.out) / "contact_sheet.png";
  if (write_beside_frames("stylize", "the contact sheet", [&] { shot.write_contact_sheet(sheet.string()); }))
    std::cout << "contact sheet: " << sheet.string() << "\n";
  if (!o.video) return;
  if (o.format != "png" || !consecutive(o.frames)) {
    std::cout << "no video: it needs consecutive PNG frames\n";
    return;
  }
  const fs::path video = fs::path(o.out) / "stylized.mp4";
  shot.inputs().refuse_file(video.string());
  // ffmpeg reads '%' in the folder as a pattern of its own: doubled, it is a plain '%'.
  const std::string pattern = printf_escaped((fs::path(o.out) / "frames").string()) + "/frame_%04d.png";
  bool encoded = false;
  if (!write_beside_frames("stylize", "the video",
                           [&] { encoded = encode_video(pattern, o.frames.front(), o.fps, video.string()); }))
    return;
  std::cout << (encoded ? "video: " + video.string() : std::string("no video: ffmpeg is not on PATH")) << "\n";
}

int interrupted_frames(const std::vector<FrameResult>& results) {
  std::cerr << "tempera stylize: interrupted after " << results.size()
            << " frame(s); they are kept, rerun the same command to resume\n";
  return kInterruptedStatus;
}

// The noise pass: the coherent frames (OUT/frames, or --noise-reference)
// boiled into OUT/noisy, resumable like the stylization; false if interrupted.
bool run_noise_pass(const Options& o) {
  NoisySequenceConfig c;
  c.exemplar = o.exemplar;
  c.reference = o.noise_reference.empty() ? (fs::path(o.out) / "frames").string() : o.noise_reference;
  c.frames = o.frames;
  c.out = (fs::path(o.out) / "noisy").string();
  c.noise_map = o.noise_map;
  c.guides = o.guides;
  c.exemplar_guides = o.exemplar_guides;  // for guided noise
  c.exemplar_frame = o.exemplar_frame;
  c.guide_weights = o.stylit.weights;
  c.options = o.noisy;
  c.options.synthesis.seed = o.stylit.synthesis.seed;
  c.options.synthesis.threads = o.stylit.synthesis.threads;
  c.resume = o.resume;
  NoisySequence sequence(c);
  FrameLine line;
  line.label = "noisy frame";
  std::vector<FrameResult> results;
  if (!cli::run_frames(sequence, results, line)) return false;
  std::cout << "noisy frames: " << c.out << "\n";
  if (o.video && consecutive(o.frames)) {
    const fs::path video = fs::path(o.out) / "noisy.mp4";
    sequence.inputs().refuse_file(video.string());
    const std::string pattern = printf_escaped(c.out) + "/frame_%04d.png";
    bool encoded = false;
    if (write_beside_frames("stylize", "the video of the noisy frames",
                            [&] { encoded = encode_video(pattern, o.frames.front(), o.fps, video.string()); }) &&
        encoded)
      std::cout << "video: " << video.string() << "\n";
  }
  return true;
}

// One line per finished sweep: "segment 1/2 (frames 1-8): level 4/4 forward sweep, 12%, ETA 0:40".
bool report_sweep(const SweepProgress& p, std::size_t index, std::size_t count, const Segment& s,
                  std::chrono::steady_clock::time_point start) {
  const bool sweep_done = p.direction > 0 ? p.frame == s.last : p.frame == s.first;
  if (sweep_done) {
    const double spent = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "segment " << index + 1 << "/" << count << " (frames " << s.first << "-" << s.last << "): level "
              << p.levels - p.level << "/" << p.levels << (p.direction > 0 ? " forward" : " backward") << " sweep, "
              << std::lround(100 * p.fraction) << "%, ETA " << clock_text(spent / p.fraction * (1 - p.fraction))
              << std::endl;
  }
  return !interrupted();
}

// The coherent method's segments (all, or the one of --segment) through the
// one unit loop; the sweep lines come from the segment's progress. False if interrupted.
bool run_segments(TciaJob& job, const Options& o) {
  const std::size_t count = job.segments().size();
  const auto segment = [&](std::size_t i, const ProgressCallback&) {
    const Segment& s = job.segments()[i];
    const auto start = std::chrono::steady_clock::now();
    const SegmentResult r =
        job.run_segment(i, [&](const SweepProgress& p) { return report_sweep(p, i, count, s, start); });
    FrameResult unit;
    unit.frame = s.first;
    unit.status = r.status;
    unit.seconds = r.seconds;
    return unit;
  };
  FrameLine line;
  line.label = "segment";
  line.which = [&](std::size_t i, const FrameResult&) {
    return concat("frames ", job.segments()[i].first, "-", job.segments()[i].last);
  };
  std::vector<FrameResult> results;
  if (!run_units(job.selected(), count, segment, results, line)) return false;
  const FrameTally t = tally(results);
  std::cout << "tempera stylize: " << t.made << " segment(s) stylized, " << t.skipped
            << " skipped (already current) in " << std::fixed << std::setprecision(1) << t.seconds << " s"
            << std::defaultfloat << "; results in " << o.out << "\n";
  return true;
}

// A method written in Python (rigid): the wheel's `tempera` command and
// `python -m tempera` run it before this CLI (tempera/__main__.py).
std::string runs_in_python(const MethodEntry& method) {
  return concat("--method ", method.name, " runs in the Python package: use the pip-installed 'tempera stylize --method ",
                method.name, " ...' or 'python -m tempera stylize --method ", method.name, " ...' (", method.docs, ")");
}

// The methods with a command of their own: StyLit and the coherent method
// share this file's (run_stylit_or_tcia), which renders a scene's guides
// itself (and an exemplar scene's). Every other native method runs through
// the registry's one command (method_command.cpp), after run_stylize has
// rendered a scene's guides for it.
int run_stylit_or_tcia(const Args& args);
const std::map<std::string, int (*)(const Args&)>& method_commands() {
  static const std::map<std::string, int (*)(const Args&)> commands = {
      {"stylit", run_stylit_or_tcia},
      {"tcia", run_stylit_or_tcia},
  };
  return commands;
}

}  // namespace

std::string method_of(const Args& args) {
  std::string method = "stylit";
  for (std::size_t i = 0; i + 1 < args.size(); ++i)
    if (args[i] == "--method") method = args[i + 1];
  return method;
}

int run_stylize(const Args& args) {
  const MethodEntry& method = find_method(method_of(args));  // before its options are taken for stylit's
  if (!method.python_command.empty()) throw ValueError(runs_in_python(method));
  const auto command = method_commands().find(method.name);
  if (command != method_commands().end()) return command->second(args);
  Args with_guides;
  try {
    with_guides = with_scene_guides(args);  // SCENE.blend: its guides first
  } catch (const CancelledError&) {
    return report_interrupted("stylize");
  }
  return run_registered_method(method, with_guides);
}

namespace {

int run_stylit_or_tcia(const Args& args) {
  if (ArgReader(args, "stylize").wants_help() || args.empty()) {
    std::cout << stylize_help();
    return args.empty() ? 2 : 0;
  }
  Options o = parse(args);  // usage errors propagate: exit status 2
  catch_interrupts();
  std::vector<FrameResult> results;
  try {
    const bool guide_map = !o.noise_map.empty() && !fs::is_regular_file(o.noise_map);
    if (!o.scene.empty() && (o.noise_reference.empty() || guide_map || o.noisy.noise_guides > 0)) render_guides(o, o.scene, o.frames_text, o.guides);
    if (!o.exemplar_scene.empty() && (o.noise_reference.empty() || o.noisy.noise_guides > 0)) {
      o.exemplar_guides = (fs::path(o.out) / "exemplar_guides").string();
      o.exemplar_frame = o.exemplar_frame.value_or(1);
      render_guides(o, o.exemplar_scene, std::to_string(*o.exemplar_frame), o.exemplar_guides);
    }
    if (!o.noise_reference.empty()) {  // boil the given coherent frames
      if (!run_noise_pass(o)) return interrupted_frames(results);
      return 0;
    }
    StylizeJobConfig config;
    config.exemplar = o.exemplar;
    config.exemplar_guides = o.exemplar_guides;
    config.exemplar_frame = o.exemplar_frame;
    config.guides = o.guides;
    config.frames = o.frames;
    config.out = (fs::path(o.out) / "frames").string();
    config.format = o.format;
    config.stylit = o.stylit;
    config.resume = o.resume;
    if (o.method == "tcia") {
      TciaJobConfig coherent;
      static_cast<LightPathShotConfig&>(coherent) = config;
      coherent.weights = o.stylit.weights;
      coherent.keys = o.keys;
      coherent.tcia = o.tcia;
      coherent.lines = o.lines;
      coherent.layers = o.layers;
      coherent.layer_order = o.layer_order.value_or("depth");
      coherent.segment = o.segment;
      coherent.orientation = o.orientation;
      TciaJob job(coherent);
      for (const auto& w : job.warnings()) std::cerr << "tempera stylize: warning: " << w << "\n";
      if (!run_segments(job, o)) return report_interrupted("stylize", "segment");
      if (!o.segment) write_extras(job.shot(), o);  // a segment is a farm task: the finish writes them
      if (o.noisy.noise > 0 && !run_noise_pass(o)) return report_interrupted("stylize", "segment");
      return 0;
    }
    StylizeJob job(config);
    for (const auto& w : job.warnings()) std::cerr << "tempera stylize: warning: " << w << "\n";
    if (!run_frames(job, results)) return interrupted_frames(results);
    write_extras(job.shot(), o);
    print_summary(results, o.out);
    if (o.noisy.noise > 0 && !run_noise_pass(o)) return interrupted_frames(results);
  } catch (const CancelledError&) {
    return interrupted_frames(results);
  }  // ValueError (bad values in the files or options) reaches main(): exit status 2
  return 0;
}

}  // namespace
}  // namespace tempera::cli

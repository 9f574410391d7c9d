// `tempera stylize`: a whole shot in one command. Sends each method to its
// command: the registry's one command (method_command.cpp) for every method
// with a job factory, StyLit included; the coherent method (tcia), which
// solves segments rather than frames, to its own below. Both render the
// guides through background Blender when given .blend files (or take
// existing guide caches, as a render farm does), resume, and write a contact
// sheet and a video (light_path_extras.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>

#include "cli_args.hpp"
#include "frame_loop.hpp"
#include "light_path_extras.hpp"
#include "scene_guides.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/methods/registry.hpp"
#include "tempera/methods/stylit/stylit.hpp"
#include "tempera/methods/tcia/tcia_job.hpp"

namespace fs = std::filesystem;

namespace tempera::cli {
namespace {

const char* kStylizeHelpText =
    "usage: tempera stylize SCENE.blend --exemplar STYLE.png (--exemplar-scene EXEMPLAR.blend |\n"
    "                       --exemplar-guides DIR) --frames A-B --out DIR [options]\n"
    "       tempera stylize --guides DIR --exemplar STYLE.png --exemplar-guides DIR --frames A-B\n"
    "                       --out DIR [options]\n"
    "       tempera stylize --method M --help   (each method's inputs and options)\n"
    "\n"
    "Stylizes an animation with StyLit (light-path guides) from a painted exemplar, or with\n"
    "another method (--method). With SCENE.blend the scene's guides are rendered first with\n"
    "background Blender into --guides (default OUT/guides), and with --exemplar-scene the\n"
    "exemplar's guides into OUT/exemplar_guides; guide frames already current are reused.\n"
    "The second form needs no Blender: it reads existing guide caches (render farms).\n"
    "\n"
    "@DETAILS@"
    "\n"
    "inputs:\n"
    "  --exemplar FILE         the painting, made on the exemplar render (same aspect)\n"
    "  --guides DIR            guide cache of the animation (default OUT/guides with SCENE)\n"
    "  --frames RANGE          frames to stylize, e.g. 1-24 or 1-10,15\n"
    "  --out DIR               output folder\n"
    "  --format F              png (default) | exr (float, linear as painted)\n"
    "  --no-resume             stylize every frame again, even if current\n"
    "@EXTRAS@"
    "\n"
    "StyLit (--method stylit, the default):\n"
    "@STYLIT@"
    "\n"
    "method:\n"
    "  --method M              the method (default stylit); each has its own options\n"
    "                          (tempera stylize --method M --help):\n"
    "@METHODS@"
    "\n"
    "the coherent method (--method tcia): the whole shot in forward and backward sweeps along\n"
    "the motion: consecutive frames with velocity_forward/backward and occlusion_forward/backward;\n"
    "StyLit's options above and:\n"
    "@TCIA@"
    "\n"
    "guide rendering (SCENE.blend / --exemplar-scene only):\n"
    "  --samples N             Cycles samples of the guide renders (default 16)\n"
    "  --blender PATH          Blender to run (default: $TEMPERA_BLENDER or 'blender')\n"
    "  --addon-path DIR        folder holding the tempera package\n"
    "  --max-image-pixels N    refuse images declaring more pixels (default 50000000;\n"
    "                          also $TEMPERA_MAX_IMAGE_PIXELS)\n"
    "\n"
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

// The overview: StyLit's outputs and resume, the core's flags, the
// light-path extras, StyLit's and the coherent method's options (their
// registry entries') and the methods.
std::string stylize_help() {
  std::string text = kStylizeHelpText;
  const auto put = [&](const std::string& key, const std::string& value) { text.replace(text.find(key), key.size(), value); };
  put("@DETAILS@", find_method("stylit").help_details);  // its outputs and resume
  put("@EXTRAS@", light_path_extras_help());
  put("@STYLIT@", find_method("stylit").options_help);
  put("@METHODS@", methods_help());
  put("@TCIA@", find_method("tcia").options_help);
  return text;
}

// The coherent method's command line.
struct Options {
  std::string scene, exemplar, exemplar_guides, guides, frames_text, out;
  std::optional<int> exemplar_frame;
  std::vector<int> frames;
  StylitOptions stylit;  // --weights, --temporal and the engine flags, as StyLit takes them
  LightPathExtras extras;
  GuideRender render;
  std::string format = "png";
  bool resume = true;
  // Its options get the engine flags given (recorded in order) on its own
  // defaults, and --temporal if given.
  std::vector<KeyFile> keys;
  std::vector<LayerFile> layers;
  std::vector<std::pair<std::string, KeyFile>> layer_keys;  // --layer-key, added to their layers
  std::optional<std::string> layer_order;
  std::optional<std::pair<int, int>> segment;
  TciaOptions tcia = default_tcia_options();
  TciaLineOptions lines;
  TciaOrientationOptions orientation;
  std::vector<std::pair<std::string, std::string>> engine_flags;
  bool temporal_given = false;
};

std::pair<int, int> parse_segment(const std::string& text) {
  const std::vector<int> frames = parse_frames(text);
  if (text.find(',') != std::string::npos || frames.size() < 2)
    throw ValueError(concat("--segment expects A-B (from one key to the next), got '", text, "'"));
  return {frames.front(), frames.back()};
}

// An engine option (recorded, for the coherent method's own defaults) or one of its own.
bool set_engine_flag(Options& o, const std::string& flag, ArgReader& r) {
  std::string text;
  auto value = [&] { return text = r.value(flag); };
  if (set_from_flag(o.stylit.synthesis, synthesis_option_table(), flag.substr(2), value)) {
    o.engine_flags.emplace_back(flag.substr(2), text);
    return true;
  }
  return set_from_flag(o.tcia, tcia_option_table(), flag.substr(2), value) ||
         set_from_flag(o.lines, tcia_line_option_table(), flag.substr(2), value) ||
         set_from_flag(o.orientation, tcia_orientation_option_table(), flag.substr(2), value);
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
    else if (flag == "--exemplar-guides") o.exemplar_guides = r.value(flag);
    else if (flag == "--exemplar-frame") o.exemplar_frame = r.number<int>(flag);
    else if (flag == "--guides") o.guides = r.value(flag);
    else if (flag == "--frames") o.frames = parse_frames(o.frames_text = r.value(flag));
    else if (flag == "--out") o.out = r.value(flag);
    else if (flag == "--weights") parse_guide_weights(r.value(flag), o.stylit.weights);
    else if (set_from_flag(o.stylit, stylit_option_table(), flag.substr(2), [&] { return r.value(flag); }))
      o.temporal_given |= flag == "--temporal";  // --temporal, --quality
    else if (flag == "--format") o.format = r.value(flag);
    else if (flag == "--no-resume") o.resume = false;
    else if (flag == "--samples") o.render.samples = std::to_string(r.number<int>(flag));
    else if (flag == "--blender") o.render.blender.blender = r.value(flag);
    else if (flag == "--addon-path") o.render.blender.addon = r.value(flag);
    else if (flag == "--max-image-pixels") set_max_image_pixels(r.number<std::int64_t>(flag));
    else if (flag == "--method") r.value(flag);  // how we got here
    else if (flag == "--key") o.keys.push_back(parse_key(r.value(flag)));
    else if (flag == "--layer") o.layers.push_back(parse_layer(r.value(flag)));
    else if (flag == "--layer-key") o.layer_keys.push_back(parse_layer_key(r.value(flag)));
    else if (flag == "--layer-order") o.layer_order = r.value(flag);
    else if (flag == "--segment") o.segment = parse_segment(r.value(flag));
    else if (take_light_path_flag(o.extras, flag, r)) continue;
    else if (!set_engine_flag(o, flag, r))
      throw ValueError(concat("unknown option '", flag, "' (see tempera stylize --help)"));
  }
  add_layer_keys(o.layers, o.layer_keys);
  for (const auto& [flag, text] : o.engine_flags)
    set_from_flag(o.tcia.synthesis, synthesis_option_table(), flag, [&] { return text; });
  if (o.temporal_given) o.tcia.temporal_weight = o.stylit.temporal_weight;
  validate(o.stylit.synthesis);
  if (o.exemplar.empty()) throw ValueError("--exemplar is required (the painting)");
  if (o.frames.empty()) throw ValueError("--frames is required (e.g. --frames 1-24)");
  if (o.out.empty()) throw ValueError("--out is required (the output folder)");
  JobConfig config;
  config.exemplar = o.exemplar, config.frames = o.frames, config.format = o.format;
  check_light_path_extras(o.extras, config, o.segment.has_value());
  if (!o.extras.noise_reference.empty()) {  // the coherent frames are given: no stylization
    if (o.guides.empty() && !o.scene.empty()) o.guides = (fs::path(o.out) / "guides").string();
    return o;
  }
  if (o.extras.exemplar_scene.empty() == o.exemplar_guides.empty())
    throw ValueError("give one of --exemplar-scene EXEMPLAR.blend or --exemplar-guides DIR");
  if (o.scene.empty() && o.guides.empty())
    throw ValueError("give SCENE.blend as the first argument, or --guides DIR with an existing guide cache");
  if (o.guides.empty()) o.guides = (fs::path(o.out) / "guides").string();
  return o;
}

// The core's config of the command (OUT, not OUT/frames), for the video and the noise pass.
JobConfig command_config(const Options& o) {
  JobConfig config;
  config.exemplar = o.exemplar, config.guides = o.guides, config.frames = o.frames, config.out = o.out;
  config.format = o.format, config.resume = o.resume;
  return config;
}

bool run_noise_pass(const Options& o) {
  NoisePassInputs in;
  in.config = command_config(o);
  in.exemplar_guides = o.exemplar_guides, in.exemplar_frame = o.exemplar_frame;
  in.weights = o.stylit.weights, in.synthesis = o.stylit.synthesis;
  return cli::run_noise_pass(o.extras, in);
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

TciaJobConfig job_config(const Options& o) {
  TciaJobConfig c;
  c.exemplar = o.exemplar;
  c.exemplar_guides = o.exemplar_guides;
  c.exemplar_frame = o.exemplar_frame;
  c.guides = o.guides;
  c.frames = o.frames;
  c.out = (fs::path(o.out) / "frames").string();
  c.format = o.format;
  c.resume = o.resume;
  c.weights = o.stylit.weights;
  c.keys = o.keys;
  c.tcia = o.tcia;
  c.lines = o.lines;
  c.layers = o.layers;
  c.layer_order = o.layer_order.value_or("depth");
  c.segment = o.segment;
  c.orientation = o.orientation;
  return c;
}

// The coherent method: segments, then (unless a farm's segment) the contact
// sheet and the video, then the noise pass.
int run_tcia(const Args& args) {
  if (ArgReader(args, "stylize").wants_help()) {
    std::cout << stylize_help();
    return 0;
  }
  Options o = parse(args);  // usage errors propagate: exit status 2
  catch_interrupts();
  const auto interrupted_segments = [] { return report_interrupted("stylize", "segment"); };
  try {
    const LightPathExtras& e = o.extras;
    const bool guide_map = !e.noise_map.empty() && !fs::is_regular_file(e.noise_map);
    if (!o.scene.empty() && (e.noise_reference.empty() || guide_map || e.noisy.noise_guides > 0))
      render_scene_guides(o.render, o.scene, o.frames_text, o.guides);
    if (!e.exemplar_scene.empty() && (e.noise_reference.empty() || e.noisy.noise_guides > 0)) {
      o.exemplar_frame = o.exemplar_frame.value_or(1);
      o.exemplar_guides = render_exemplar_scene(e, o.render, o.out, *o.exemplar_frame);
    }
    if (!e.noise_reference.empty()) return run_noise_pass(o) ? 0 : interrupted_segments();  // boil the given frames
    TciaJob job(job_config(o));
    for (const auto& w : job.warnings()) std::cerr << "tempera stylize: warning: " << w << "\n";
    if (!run_segments(job, o)) return interrupted_segments();
    if (!o.segment) {  // a segment is a farm task: the finish writes the sheet and the video
      const fs::path sheet = fs::path(o.out) / "contact_sheet.png";
      if (write_beside_frames("stylize", "the contact sheet", [&] { job.shot().write_contact_sheet(sheet.string()); }))
        std::cout << "contact sheet: " << sheet.string() << "\n";
      write_video(e, job.shot().inputs(), command_config(o));
    }
    if (e.noise() && !run_noise_pass(o)) return interrupted_segments();
  } catch (const CancelledError&) {
    return interrupted_segments();
  }  // ValueError (bad values in the files or options) reaches main(): exit status 2
  return 0;
}

// A method written in Python (rigid): the wheel's `tempera` command and
// `python -m tempera` run it before this CLI (tempera/__main__.py).
std::string runs_in_python(const MethodEntry& method) {
  return concat("--method ", method.name, " runs in the Python package: use the pip-installed 'tempera stylize --method ",
                method.name, " ...' or 'python -m tempera stylize --method ", method.name, " ...' (", method.docs, ")");
}

bool names_a_method(const Args& args) { return std::find(args.begin(), args.end(), "--method") != args.end(); }

}  // namespace

std::string method_of(const Args& args) {
  std::string method = "stylit";
  for (std::size_t i = 0; i + 1 < args.size(); ++i)
    if (args[i] == "--method") method = args[i + 1];
  return method;
}

int run_stylize(const Args& args) {
  if (args.empty() || (ArgReader(args, "stylize").wants_help() && !names_a_method(args))) {
    std::cout << stylize_help();  // the overview
    return args.empty() ? 2 : 0;
  }
  const MethodEntry& method = find_method(method_of(args));
  if (!method.python_command.empty()) throw ValueError(runs_in_python(method));
  if (method.unit == "segment") return run_tcia(args);  // the one method that solves segments, not frames
  return run_registered_method(method, args);
}

}  // namespace tempera::cli

// `tempera stylize --method NAME` for a method the registry runs by its job
// factory (methods/registry.hpp: make_job, or make_segment_job for the
// segment unit): one command for every such method, built in or a plug-in, with the core's flags, a scene's guides
// rendered first, resume, progress lines, Ctrl-C and contact sheet, so that
// a method needs no command of its own (docs/adding_a_method.md). A
// light-path method (StyLit) also gets the exemplar scene, the video and
// the noise pass (light_path_extras.hpp).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "cli_args.hpp"
#include "frame_loop.hpp"
#include "light_path_extras.hpp"
#include "scene_guides.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/engine/synthesis_options.hpp"

namespace fs = std::filesystem;

namespace tempera::cli {
namespace {

// The help's note on the default exemplar, if the method has one.
std::string method_default_exemplar(const MethodEntry& m) {
  if (m.default_exemplar.empty()) return "";
  if (m.default_exemplar == kJobMadeExemplar)
    return " (left out, or 'generated': the project's own,\n"
           "                          which the job writes into OUT/exemplar_generated_...)";
  if (m.default_exemplar == kKitExemplar)
    return " (left out with the exemplar's guides and scene:\n"
           "                          the Python package's tempera uses the bundled exemplar kit)";
  return concat(" (left out: the Python package's tempera generates\n"
                "                          the project's own ", m.default_exemplar, " into OUT/exemplar_generated_",
                m.default_exemplar, ")");
}

std::string method_help(const MethodEntry& m) {
  const std::string exemplar_guides = m.light_path_guides ? " (--exemplar-guides DIR | --exemplar-scene FILE)" : "";
  return concat("usage: tempera stylize --method ", m.name, " --guides DIR --exemplar PATH", exemplar_guides,
                " --frames A-B --out DIR [options]\n"
                "       tempera stylize SCENE.blend --method ",
                m.name, " --exemplar PATH", exemplar_guides, " --frames A-B --out DIR [--samples N] [options]\n\n",
                m.title, " (", m.paper, "): ", m.summary, ". See ", m.docs, ".\n\n", m.help_details,
                m.help_details.empty() ? "" : "\n",
                "inputs and outputs:\n"
                "  --exemplar PATH         the exemplar",
                method_default_exemplar(m), "\n"
                "  --guides DIR            guide cache of the animation (with SCENE.blend: rendered there first\n"
                "                          by background Blender, default OUT/guides, as tempera render-guides\n"
                "                          does: --samples N, --blender PATH, --addon-path DIR)\n"
                "  --frames RANGE          frames to make, e.g. 1-24\n"
                "  --out DIR               output folder\n"
                "  --format F              png (default) | exr\n"
                "  --no-resume             make every frame again, even if current\n"
                "  --max-image-pixels N    refuse images declaring more pixels (default 50000000)\n",
                m.light_path_guides ? "\naround the frames (a light-path method's):\n" + light_path_extras_help()
                                    : "  --no-video              accepted: this method writes frames, no video\n",
                "\nmethod options:\n", m.options_help.empty() ? "  (none)\n" : m.options_help,
                "\nExit status: 0 done, 1 error (files, Blender), 2 bad usage or bad values, 130 interrupted.\n");
}

// What the command line asks: the core's config, the method's own options
// (the flag without "--" and its text, "" for a switch alone), the scene
// whose guides are rendered first, and a light-path method's extras.
struct Request {
  std::string scene;
  std::string frames_text;  // --frames as given, for the scene's render
  GuideRender render;  // of the scene and the exemplar scene
  JobConfig config;
  MethodOptions options;
  LightPathExtras extras;

  const std::string* option(const std::string& flag) const {
    for (auto it = options.rbegin(); it != options.rend(); ++it)
      if (it->first == flag) return &it->second;
    return nullptr;
  }
};

void check_required(const MethodEntry& method, const Request& q) {
  const JobConfig& config = q.config;
  const bool job_makes_one = method.default_exemplar == kJobMadeExemplar;
  if (config.exemplar.empty() && method.default_exemplar == kKitExemplar)
    throw ValueError("--exemplar is required here; the Python package's 'tempera stylize' uses the bundled "
                     "exemplar kit (a painted sphere on a table) when --exemplar, --exemplar-guides and "
                     "--exemplar-scene are left out");
  if (config.exemplar.empty() && !method.default_exemplar.empty() && !job_makes_one)
    throw ValueError(concat("--exemplar is required here; the Python package's 'tempera stylize' uses the project's "
                            "own ", method.default_exemplar, " exemplar when it is left out (or write it with "
                            "'tempera exemplar ", method.default_exemplar, " --out DIR')"));
  if (config.exemplar.empty() && !job_makes_one) throw ValueError("--exemplar is required (the exemplar)");
  if (config.frames.empty()) throw ValueError("--frames is required (e.g. --frames 1-24)");
  if (config.out.empty()) throw ValueError("--out is required (the output folder)");
  const bool boil_only = !q.extras.noise_reference.empty();  // no stylization
  if (config.guides.empty() && !boil_only)
    throw ValueError("give SCENE.blend as the first argument, or --guides DIR with an existing guide cache");
  if (!method.light_path_guides) return;
  check_light_path_extras(q.extras, config, q.option("segment") != nullptr);
  if (!boil_only && q.extras.exemplar_scene.empty() == (q.option("exemplar-guides") == nullptr))
    throw ValueError("give one of --exemplar-scene EXEMPLAR.blend or --exemplar-guides DIR");
}

Request parse(const MethodEntry& method, const Args& args) {
  Request q;
  std::size_t first = 0;
  if (!args.empty() && args[0].rfind("--", 0) != 0) q.scene = args[first++];  // SCENE.blend
  const Args tail(args.begin() + first, args.end());
  JobConfig& config = q.config;
  ArgReader r(tail, "stylize");
  while (r.more()) {
    const std::string flag = r.flag();
    if (flag == "--method") r.value(flag);  // how we got here
    else if (flag == "--exemplar") config.exemplar = r.value(flag);
    else if (flag == "--guides") config.guides = r.value(flag);
    else if (flag == "--frames") config.frames = parse_frames(q.frames_text = r.value(flag));
    else if (flag == "--out") config.out = r.value(flag);
    else if (flag == "--format") config.format = r.value(flag);
    else if (flag == "--no-resume") config.resume = false;
    else if (flag == "--max-image-pixels") set_max_image_pixels(r.number<std::int64_t>(flag));
    else if (flag == "--samples") q.render.samples = std::to_string(r.number<int>(flag));
    else if (flag == "--blender") q.render.blender.blender = r.value(flag);
    else if (flag == "--addon-path") q.render.blender.addon = r.value(flag);
    else if (method.light_path_guides && take_light_path_flag(q.extras, flag, r)) continue;
    else if (flag == "--no-video") continue;  // the other methods write no video: a farm script passes it to all
    else q.options.emplace_back(flag.substr(2), r.optional_value() ? r.value(flag) : "");  // the method names unknown ones
  }
  if (config.guides.empty() && !q.scene.empty() && !config.out.empty())
    config.guides = (fs::path(config.out) / "guides").string();
  check_required(method, q);
  if (method.check_options) method.check_options(q.options);  // before any render: a typo costs none
  return q;
}

// Boiling given frames (--noise-reference) reads the shot's guides only for
// a guide as the noise map or for guided noise, the exemplar's only for the
// latter: else their scenes are not rendered.
bool reads_guides(const LightPathExtras& e, bool exemplar) {
  if (e.noise_reference.empty() || e.noisy.noise_guides > 0) return true;
  return !exemplar && !e.noise_map.empty() && !fs::is_regular_file(e.noise_map);
}

// A light-path method's exemplar scene rendered (into OUT/exemplar_guides,
// its frame 1 unless --exemplar-frame says), passed on as --exemplar-guides.
void render_exemplar_guides(Request& q) {
  if (q.extras.exemplar_scene.empty() || !reads_guides(q.extras, true)) return;
  const std::string* given = q.option("exemplar-frame");
  const int frame = given ? parse_number<int>(*given, "--exemplar-frame") : 1;
  q.options.emplace_back("exemplar-guides", render_exemplar_scene(q.extras, q.render, q.config.out, frame));
  if (!given) q.options.emplace_back("exemplar-frame", "1");
}

// The noise pass's inputs from the request: the light-path guides' weights,
// seed and threads given to the method (errors in them are the method's).
NoisePassInputs noise_inputs(const Request& q) {
  NoisePassInputs in;
  in.config = q.config;
  for (const auto& [flag, text] : q.options) {
    if (flag == "exemplar-guides") in.exemplar_guides = text;
    else if (flag == "exemplar-frame") in.exemplar_frame = parse_number<int>(text, "--exemplar-frame");
    else if (flag == "weights") parse_guide_weights(text, in.weights);
    else if (flag == "seed" || flag == "threads") set_from_text(in.synthesis, synthesis_option_table(), flag, text);
  }
  return in;
}

void print_summary(const std::vector<FrameResult>& results, const FrameJob& job, const std::string& out) {
  const FrameTally t = tally(results);
  int counted = 0;
  double flicker_sum = 0;
  for (const auto& r : results)
    if (std::isfinite(r.flicker)) flicker_sum += r.flicker, ++counted;
  const std::string summary = job.summary();
  std::cout << "tempera stylize: " << t.made << " frame(s) stylized, " << t.skipped
            << " skipped (already current) in " << std::fixed << std::setprecision(1) << t.seconds << " s";
  if (counted) std::cout << "; mean flicker " << std::setprecision(4) << flicker_sum / counted;
  std::cout << std::defaultfloat << (summary.empty() ? "" : "; ") << summary << "; results in " << out << "\n";
}

// The job's frames with its contact sheet (and a light-path method's video);
// false if interrupted.
bool make_frames(const MethodEntry& method, const Request& q) {
  const std::unique_ptr<FrameJob> job = make_method_job(method, q.config, q.options);  // frames in OUT/frames
  job->inputs().refuse_folder(q.config.out);  // the contact sheet goes there too
  for (const auto& w : job->warnings()) std::cerr << "tempera stylize: warning: " << w << "\n";
  FrameLine line;
  line.details = [](std::ostream& out, const FrameResult& r) {
    if (std::isfinite(r.flicker)) out << ", flicker " << std::fixed << std::setprecision(4) << r.flicker;
    else if (r.status != "skipped" && r.source_coverage > 0) out << ", source coverage " << r.source_coverage;
  };
  line.eta = true;
  std::vector<FrameResult> results;
  if (!run_frames(*job, results, line)) return false;
  print_summary(results, *job, q.config.out);
  const fs::path sheet = fs::path(q.config.out) / "contact_sheet.png";
  if (job->has_contact_sheet() &&
      write_beside_frames("stylize", "the contact sheet", [&] { job->write_contact_sheet(sheet.string()); }))
    std::cout << "contact sheet: " << sheet.string() << "\n";
  if (method.light_path_guides) write_video(q.extras, job->inputs(), q.config);
  return true;
}

// One line per finished stage of a segment: "segment 1/2 (frames 1-8):
// level 4/4 forward sweep, 12%, ETA 0:40"; false (cancel) once interrupted.
StageProgress stage_lines(std::size_t index, std::size_t count, const Segment& s) {
  const auto start = std::chrono::steady_clock::now();
  return [=](double fraction, const std::string& finished) {
    if (!finished.empty()) {
      const double spent = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::cout << "segment " << index + 1 << "/" << count << " (frames " << s.first << "-" << s.last << "): "
                << finished << ", " << std::lround(100 * fraction) << "%, ETA "
                << clock_text(spent / fraction * (1 - fraction)) << std::endl;
    }
    return !interrupted();
  };
}

// The segments of a method whose unit is the segment (all, or a farm task's
// one) through the one unit loop; a run over the whole shot also writes the
// contact sheet (and a light-path method's video). False if interrupted.
bool make_segments(const MethodEntry& method, const Request& q) {
  const std::unique_ptr<SegmentJob> job = make_method_segment_job(method, q.config, q.options);  // OUT/frames
  job->inputs().refuse_folder(q.config.out);  // the contact sheet goes there too
  for (const auto& w : job->warnings()) std::cerr << "tempera stylize: warning: " << w << "\n";
  const std::vector<Segment>& segments = job->segments();
  const auto run = [&](std::size_t i, const ProgressCallback&) {
    return job->run_unit(i, stage_lines(i, segments.size(), segments[i]));
  };
  FrameLine line;
  line.label = "segment";
  line.which = [&](std::size_t i, const FrameResult&) { return concat("frames ", segments[i].first, "-", segments[i].last); };
  std::vector<FrameResult> results;
  if (!run_units(job->selected(), segments.size(), run, results, line)) return false;
  const FrameTally t = tally(results);
  std::cout << "tempera stylize: " << t.made << " segment(s) stylized, " << t.skipped
            << " skipped (already current) in " << std::fixed << std::setprecision(1) << t.seconds << " s"
            << std::defaultfloat << "; results in " << q.config.out << "\n";
  if (!job->whole_shot()) return true;  // a farm task: the finish writes the sheet and the video
  const fs::path sheet = fs::path(q.config.out) / "contact_sheet.png";
  if (write_beside_frames("stylize", "the contact sheet", [&] { job->write_contact_sheet(sheet.string()); }))
    std::cout << "contact sheet: " << sheet.string() << "\n";
  if (method.light_path_guides) write_video(q.extras, job->inputs(), q.config);
  return true;
}

}  // namespace

int run_registered_method(const MethodEntry& method, const Args& args) {
  if (ArgReader(args, "stylize").wants_help()) {
    std::cout << method_help(method);
    return 0;
  }
  Request q = parse(method, args);  // usage errors: exit status 2
  catch_interrupts();
  const bool segments = method.unit == "segment";
  const auto stopped = [&] { return report_interrupted("stylize", segments ? "segment" : "frame"); };
  try {
    if (!q.scene.empty() && reads_guides(q.extras, false))
      render_scene_guides(q.render, q.scene, q.frames_text, q.config.guides);
    render_exemplar_guides(q);
    if (q.extras.noise_reference.empty()) {  // else boil the given frames only
      if (!(segments ? make_segments(method, q) : make_frames(method, q))) return stopped();
    }
    if (q.extras.noise() && !run_noise_pass(q.extras, noise_inputs(q))) return stopped();
  } catch (const CancelledError&) {
    return stopped();
  }  // ValueError (bad values in the files or options) reaches main(): exit status 2
  return 0;
}

}  // namespace tempera::cli

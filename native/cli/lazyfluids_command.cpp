// `tempera stylize --method lazyfluids`: LazyFluids over a guide cache
// (lazyfluids_job.hpp), frame by frame with resume, then a contact sheet.
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "cli_args.hpp"
#include "frame_loop.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/methods/lazyfluids/lazyfluids_job.hpp"

namespace fs = std::filesystem;

namespace tempera::cli {
namespace {

const char* kLazyFluidsHelpText =
    "usage: tempera stylize --method lazyfluids --guides DIR --exemplar PATH --frames A-B --out DIR\n"
    "                       [options]\n"
    "       tempera stylize SCENE.blend --method lazyfluids --exemplar PATH --frames A-B --out DIR\n"
    "                       [--samples N] [options]\n"
    "\n"
    "LazyFluids (Jamriska et al. 2015): an RGBA exemplar of a fluid element (smoke, fire,\n"
    "ink) carried along the flow inside the target alpha, every exemplar patch used equally\n"
    "often per boundary / interior segment so that it never washes out (docs/lazyfluids.md).\n"
    "Target alpha: the guide cache's 'alpha'; flow: 'fluid_velocity' (p moves to p + F in\n"
    "the next frame), else 'velocity_forward', else zero (with a warning).\n"
    "\n"
    "outputs:\n"
    "  OUT/frames/frame_0001.png ...     RGBA frames, transparent outside (each written atomically)\n"
    "  OUT/frames/tempera_lazyfluids/    per frame the float state and the resume record\n"
    "  OUT/contact_sheet.png             the exemplar followed by the frames\n"
    "\n"
    "inputs:\n"
    "  --exemplar PATH         RGBA image, or a folder of RGBA frames (a video exemplar,\n"
    "                          sorted by name, looped when shorter than the shot)\n"
    "  --guides DIR            guide cache of the animation (frame_####.exr); with SCENE.blend\n"
    "                          its guides are rendered there first (default OUT/guides) by\n"
    "                          background Blender, as tempera render-guides does (--samples N,\n"
    "                          --blender PATH, --addon-path DIR); current frames are reused\n"
    "  --frames RANGE          consecutive frames, e.g. 1-120\n"
    "  --out DIR               output folder\n"
    "\n"
    "method:\n"
    "@OPTIONS@"
    "  (any engine option of 'tempera synth --help'; LazyFluids' defaults: --patch-size 5\n"
    "  --usage uniform)\n"
    "  --format F              png (default) | exr\n"
    "  --no-resume             stylize every frame again, even if current\n"
    "\n"
    "Resume: a frame is skipped when its record matches the settings, the exemplar, its guide\n"
    "files and the frame before; rerun the same command after an interruption (Ctrl-C stops\n"
    "within the current frame; finished frames are kept).\n"
    "Exit status: 0 done, 1 error (files), 2 bad usage or bad values, 130 interrupted.\n";

std::string lazyfluids_help() {
  std::string text = kLazyFluidsHelpText;
  text.replace(text.find("@OPTIONS@"), 9, flags_help<LazyFluidsOptions>(lazyfluids_option_table()));
  for (const std::string flag : {"--rotations", "--warm-start"}) {  // also bare switches
    const std::size_t at = text.find(flag + " V  ");
    text.replace(at, flag.size() + 4, flag + " [V]");
  }
  return text;
}

struct Options {
  LazyFluidsJobConfig job;
  std::string out;
};

Options parse(const Args& args) {
  Options o;
  ArgReader r(args, "stylize");
  while (r.more()) {
    const std::string flag = r.flag();
    auto value = [&] { return r.value(flag); };
    if (flag == "--method") r.value(flag);  // lazyfluids: how we got here
    else if (flag == "--exemplar") o.job.exemplar = r.value(flag);
    else if (flag == "--guides") o.job.guides = r.value(flag);
    else if (flag == "--frames") o.job.frames = parse_frames(r.value(flag));
    else if (flag == "--out") o.out = r.value(flag);
    else if (flag == "--format") o.job.format = r.value(flag);
    else if (flag == "--no-resume") o.job.resume = false;
    else if (flag == "--rotations" && !r.optional_value()) o.job.options.rotations = true;  // bare switches
    else if (flag == "--warm-start" && !r.optional_value()) o.job.options.warm_start = true;
    else if (!set_from_flag(o.job.options, lazyfluids_option_table(), flag.substr(2), value) &&
             !set_from_flag(o.job.options.synthesis, synthesis_option_table(), flag.substr(2), value))
      throw ValueError(concat("unknown option '", flag, "' for --method lazyfluids (see tempera stylize --method "
                              "lazyfluids --help)"));
  }
  if (o.job.exemplar.empty()) throw ValueError("--exemplar is required (the RGBA exemplar or a folder of frames)");
  if (o.job.guides.empty()) throw ValueError("--guides is required (the guide cache with alpha and the flow)");
  if (o.job.frames.empty()) throw ValueError("--frames is required (e.g. --frames 1-120)");
  if (o.out.empty()) throw ValueError("--out is required (the output folder)");
  o.job.out = (fs::path(o.out) / "frames").string();
  return o;
}

// Every frame, one line each with the source coverage; false if interrupted.
bool run_frames(LazyFluidsJob& job) {
  FrameLine line;
  line.details = [](std::ostream& out, const FrameResult& r) {
    if (r.status != "skipped") out << ", source coverage " << r.source_coverage;
  };
  std::vector<FrameResult> results;
  if (!cli::run_frames(job, results, line)) return false;
  const FrameTally t = tally(results);
  std::cout << "tempera stylize: " << t.made << " frame(s) stylized, " << t.skipped
            << " skipped (already current) in " << std::fixed << std::setprecision(1) << t.seconds << " s"
            << std::defaultfloat << "\n";
  return true;
}

}  // namespace

int run_lazyfluids(const Args& args) {
  if (ArgReader(args, "stylize").wants_help()) {
    std::cout << lazyfluids_help();
    return 0;
  }
  Options o = parse(args);  // usage errors propagate: exit status 2
  catch_interrupts();
  LazyFluidsJob job(o.job);  // bad files or values: exit status 1 or 2
  job.inputs().refuse_folder(o.out);  // the contact sheet would join a video exemplar's frames
  for (const auto& w : job.warnings()) std::cerr << "tempera stylize: warning: " << w << "\n";
  if (!run_frames(job)) return report_interrupted("stylize");
  const fs::path sheet = fs::path(o.out) / "contact_sheet.png";
  if (write_beside_frames("stylize", "the contact sheet", [&] { job.write_contact_sheet(sheet.string()); }))
    std::cout << "contact sheet: " << sheet.string() << "\n";
  std::cout << "results in " << o.out << "\n";
  return 0;
}

}  // namespace tempera::cli

// `tempera stylize --method fluidymation`: Fluidymation (Platkevič et al.
// 2021) over a guide cache, frame by frame with resume (fluidymation_job.hpp).
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "cli_args.hpp"
#include "frame_loop.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/methods/fluidymation/fluidymation_job.hpp"
#include "tempera/app/image_io.hpp"

namespace fs = std::filesystem;

namespace tempera::cli {
namespace {

const char* kHelp =
    "usage: tempera stylize --method fluidymation --guides DIR --exemplar DIR [--exemplar-masks DIR]\n"
    "                       [--target-mask alpha|mask.NAME] [--flow auto|fluid|guides|masks] [--bidirectional]\n"
    "                       --frames A-B --out DIR [options]\n"
    "       tempera stylize SCENE.blend --method fluidymation --exemplar DIR ... --frames A-B\n"
    "                       --out DIR [--samples N] [options]\n"
    "\n"
    "Fluidymation (Platkevic et al. 2021): the target's masks painted with the motion of a natural\n"
    "medium filmed or simulated as a video exemplar (ink, watercolour). The exemplar's flow comes\n"
    "from its masks; the target's from the guide cache's fluid_velocity or velocity_forward, or\n"
    "from its masks.\n"
    "\n"
    "outputs:\n"
    "  OUT/frame_0001.png ...       RGBA frames (alpha = the target mask), each written atomically\n"
    "  OUT/tempera_fluidymation/    per frame the matches and a resume record\n"
    "  OUT/contact_sheet.png        the first exemplar frame followed by the frames\n"
    "\n"
    "inputs:\n"
    "  --guides DIR            guide cache of the animation; with SCENE.blend its guides are\n"
    "                          rendered there first (default OUT/guides) by background Blender,\n"
    "                          as tempera render-guides does (--samples N, --blender PATH,\n"
    "                          --addon-path DIR); current frames are reused\n"
    "  --exemplar DIR          exemplar video as frames (PNG, EXR, ...; name order); RGBA: alpha\n"
    "                          is the paint's mask, RGB: give --exemplar-masks\n"
    "  --exemplar-masks DIR    mask frames of the exemplar (first channel > 0.5 = paint)\n"
    "  --target-mask NAME      alpha (default) | mask.OB_<object> | mask.CO_<collection>\n"
    "  --flow F                auto (default: fluid, else guides, else masks, by what the cache\n"
    "                          has) | fluid (fluid_velocity: smoke, liquids) | guides\n"
    "                          (velocity_forward, exact from Blender) | masks (App. A)\n"
    "  --frames RANGE          consecutive frames, e.g. 1-48\n"
    "  --out DIR               output folder\n"
    "\n"
    "method:\n"
    "  --bidirectional         also solve the shot backward and keep, per pixel, the better pass\n"
    "@OPTIONS@"
    "  (any engine option of 'tempera synth --help'; defaults: 5x5 patches, directed orientations,\n"
    "   3 EM iterations, exact guides)\n"
    "  --format F              png (default) | exr\n"
    "  --no-resume             stylize every frame again, even if current\n"
    "\n"
    "Resume: a frame is skipped when its output, matches and record are current (same settings,\n"
    "files and every frame before it); rerun the same command after an interruption.\n"
    "Exit status: 0 done, 1 error (files), 2 bad usage or bad values, 130 interrupted.\n";

FluidymationJobConfig parse(const Args& args) {
  FluidymationJobConfig c;
  ArgReader r(args, "stylize");
  while (r.more()) {
    const std::string flag = r.flag();
    if (flag == "--method") {
      if (r.value(flag) != "fluidymation") throw ValueError("--method given twice");
    } else if (flag == "--guides") c.guides = r.value(flag);
    else if (flag == "--exemplar") c.exemplar = r.value(flag);
    else if (flag == "--exemplar-masks") c.exemplar_masks = r.value(flag);
    else if (flag == "--target-mask") c.target_mask = r.value(flag);
    else if (flag == "--flow") c.flow = parse_enum<FlowSource>(r.value(flag), "--flow");
    else if (flag == "--bidirectional") c.options.bidirectional = true;
    else if (flag == "--frames") c.frames = parse_frames(r.value(flag));
    else if (flag == "--out") c.out = r.value(flag);
    else if (flag == "--format") c.format = r.value(flag);
    else if (flag == "--no-resume") c.resume = false;
    else if (flag == "--max-image-pixels") set_max_image_pixels(r.number<std::int64_t>(flag));
    else if (!set_from_flag(c.options, fluidymation_option_table(), flag.substr(2), [&] { return r.value(flag); }) &&
             !set_from_flag(c.options.synthesis, synthesis_option_table(), flag.substr(2), [&] { return r.value(flag); }))
      throw ValueError(concat("unknown option '", flag, "' (see tempera stylize --method fluidymation --help)"));
  }
  for (const auto& [value, what] : {std::pair{&c.guides, "--guides DIR (the guide cache)"},
                                    {&c.exemplar, "--exemplar DIR (the exemplar's frames)"},
                                    {&c.out, "--out DIR (the output folder)"}})
    if (value->empty()) throw ValueError(concat(what, " is required"));
  if (c.frames.empty()) throw ValueError("--frames is required (e.g. --frames 1-48)");
  return c;
}

}  // namespace

int run_stylize_fluidymation(const Args& args) {
  if (ArgReader(args, "stylize").wants_help()) {
    std::string text = kHelp;
    text.replace(text.find("@OPTIONS@"), 9, flags_help<FluidymationOptions>(fluidymation_option_table()));
    std::cout << text;
    return 0;
  }
  FluidymationJobConfig config = parse(args);
  FluidymationJob job(config);  // bad inputs: ValueError, exit status 2
  for (const auto& w : job.warnings()) std::cerr << "tempera stylize: warning: " << w << "\n";
  catch_interrupts();
  std::vector<FrameResult> results;
  if (!run_frames(job, results)) return report_interrupted("stylize");
  const FrameTally t = tally(results);
  const fs::path sheet = fs::path(config.out) / "contact_sheet.png";
  const bool sheet_written =
      write_beside_frames("stylize", "the contact sheet", [&] { job.write_contact_sheet(sheet.string()); });
  std::cout << "tempera stylize: " << t.made << " frame(s) stylized in " << std::fixed << std::setprecision(1)
            << t.seconds << " s" << std::defaultfloat << "; flow from " << (job.flow_guide().empty() ? "masks" : job.flow_guide())
            << (sheet_written ? "; contact sheet " + sheet.string() : std::string()) << "\n";
  return 0;
}

}  // namespace tempera::cli

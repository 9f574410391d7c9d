// `tempera noisy`: Color Me Noisy on a folder of coherent frames (R), one
// output frame each (noisy.hpp). Frames are independent, so a farm may split
// the range anywhere; each finished frame is written atomically with a key
// beside it, and a rerun skips frames whose key still matches. Compiled into
// the command line only (this folder's CMakeLists.txt), which it joins by
// registering itself (cli/commands.hpp).
#include <iostream>

#include "cli_args.hpp"
#include "commands.hpp"
#include "frame_loop.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/methods/noisy/noisy_sequence.hpp"

namespace tempera::cli {
namespace {

std::string noisy_help() {
  return "usage: tempera noisy --exemplar MEDIUM.png (--reference DIR | --guides DIR) --frames A-B --out DIR\n"
         "                     [options]\n"
         "\n"
         "Makes a coherent stylized sequence boil like hand-coloured animation (Color Me Noisy,\n"
         "Fiser et al. 2014): below the width --noise the frames follow the reference frames,\n"
         "above it the medium's texture is synthesized again every frame.\n"
         "\n"
         "  --exemplar FILE         a sample of the medium (the painting, or a scan of the paper/pencil)\n"
         "  --reference DIR         the coherent frames R: DIR/<prefix>0001.png ... (default: the\n"
         "                          render of --guides, its FULL guide in display sRGB)\n"
         "  --frames RANGE          e.g. 1-24 or 1-10,15\n"
         "  --out DIR               output folder: OUT/<prefix>0001.png ...\n"
         "  --noise-map FILE|GUIDE  where the noise goes: an image of R's size, or a guide of --guides\n"
         "                          (alpha, mask.OB_Name, an AOV); 0 = R as it is, 1 = --noise\n"
         "  --guides DIR            the frames' guide cache: its render without --reference, a GUIDE\n"
         "                          noise map, --noise-guides\n"
         "  --exemplar-guides DIR   guide cache of the exemplar render (for --noise-guides)\n"
         "  --exemplar-frame N      its frame (default: the only frame in --exemplar-guides)\n"
         "  --weights NAME=W,...    light-path guide weights for --noise-guides (as tempera stylize)\n"
         "  --prefix P              frame file prefix (default frame_)\n"
         "  --no-resume             redo every frame\n"
         "\n"
         "Color Me Noisy options:\n" +
         flags_help<NoisyOptions>(noisy_option_table()) +
         "\nengine options (defaults: patch 7, mode voting, 4 EM x 2 PatchMatch, usage none):\n" +
         flags_help<SynthesisOptions>(synthesis_option_table()) +
         "\nCtrl-C stops within the current frame; finished frames are kept.\n"
         "Exit status: 0 done, 1 error, 2 bad usage, 130 interrupted.\n";
}

int run_noisy(const Args& args) {
  ArgReader r(args, "noisy");
  if (r.wants_help()) {
    std::cout << noisy_help();
    return 0;
  }
  NoisySequenceConfig c;
  std::string frames_text;
  while (r.more()) {
    const std::string flag = r.flag();
    auto value = [&] { return r.value(flag); };
    if (flag == "--exemplar") c.exemplar = value();
    else if (flag == "--reference") c.reference = value();
    else if (flag == "--frames") c.frames = parse_frames(frames_text = value());
    else if (flag == "--out") c.out = value();
    else if (flag == "--noise-map") c.noise_map = value();
    else if (flag == "--guides") c.guides = value();
    else if (flag == "--exemplar-guides") c.exemplar_guides = value();
    else if (flag == "--exemplar-frame") c.exemplar_frame = r.number<int>(flag);
    else if (flag == "--weights") parse_guide_weights(value(), c.guide_weights);
    else if (flag == "--prefix") c.prefix = value();
    else if (flag == "--no-resume") c.resume = false;
    else if (!set_from_flag(c.options, noisy_option_table(), flag.substr(2), value) &&
             !set_from_flag(c.options.synthesis, synthesis_option_table(), flag.substr(2), value))
      throw ValueError(concat("unknown option '", flag, "' (see tempera noisy --help)"));
  }
  if (c.exemplar.empty()) throw ValueError("--exemplar is required (a sample of the medium)");
  if (c.reference.empty() && c.guides.empty())
    throw ValueError("--reference is required (the folder of coherent frames), or --guides to boil the render");
  if (frames_text.empty()) throw ValueError("--frames is required (e.g. --frames 1-24)");
  if (c.out.empty()) throw ValueError("--out is required (the output folder)");
  NoisySequence sequence(c);
  catch_interrupts();
  std::vector<FrameResult> results;
  if (!run_frames(sequence, results)) return report_interrupted("noisy");
  const FrameTally t = tally(results);
  std::cout << "tempera noisy: " << t.made << " frame(s) made, " << t.skipped << " current; results in " << c.out
            << "\n";
  return 0;
}

const CommandRegistration kCommand("noisy", "add temporal noise to a coherent sequence (Color Me Noisy, resumable)",
                                   run_noisy);

}  // namespace
}  // namespace tempera::cli

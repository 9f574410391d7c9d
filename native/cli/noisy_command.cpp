// `tempera noisy`: Color Me Noisy on a folder of coherent frames (R), one
// output frame each (noisy.hpp). Frames are independent, so a farm may split
// the range anywhere; each finished frame is written atomically with a key
// beside it, and a rerun skips frames whose key still matches.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli_args.hpp"
#include "tempera/error.hpp"
#include "tempera/file_keys.hpp"
#include "tempera/image_io.hpp"
#include "tempera/noisy.hpp"

namespace fs = std::filesystem;

namespace tempera::cli {
namespace {

std::string noisy_help() {
  return "usage: tempera noisy --exemplar MEDIUM.png --reference DIR --frames A-B --out DIR [options]\n"
         "\n"
         "Makes a coherent stylized sequence boil like hand-coloured animation (Color Me Noisy,\n"
         "Fiser et al. 2014): below the width --noise the frames follow the reference frames,\n"
         "above it the medium's texture is synthesized again every frame.\n"
         "\n"
         "  --exemplar FILE         a sample of the medium (the painting, or a scan of the paper/pencil)\n"
         "  --reference DIR         the coherent frames R: DIR/<prefix>0001.png ...\n"
         "  --frames RANGE          e.g. 1-24 or 1-10,15\n"
         "  --out DIR               output folder: OUT/<prefix>0001.png ...\n"
         "  --noise-map FILE        where the noise goes (R's size; 0 = R as it is, 1 = --noise)\n"
         "  --prefix P              frame file prefix (default frame_)\n"
         "  --no-resume             redo every frame\n"
         "\n"
         "Color Me Noisy options:\n" +
         flags_help<NoisyOptions>(noisy_option_table()) +
         "\nengine options (defaults: patch 7, mode voting, 4 EM x 2 PatchMatch, usage none):\n" +
         flags_help<SynthesisOptions>(synthesis_option_table()) +
         "\nExit status: 0 done, 1 error, 2 bad usage.\n";
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text_atomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw IoError(concat("cannot write '", tmp.string(), "'"));
  }
  fs::rename(tmp, path);
}

}  // namespace

int run_noisy(const Args& args) {
  ArgReader r(args, "noisy");
  if (r.wants_help()) {
    std::cout << noisy_help();
    return 0;
  }
  std::string exemplar, reference, frames_text, out, noise_map, prefix = "frame_";
  bool resume = true;
  NoisyOptions opt = default_noisy_options();
  while (r.more()) {
    const std::string flag = r.flag();
    auto value = [&] { return r.value(flag); };
    if (flag == "--exemplar") exemplar = value();
    else if (flag == "--reference") reference = value();
    else if (flag == "--frames") frames_text = value();
    else if (flag == "--out") out = value();
    else if (flag == "--noise-map") noise_map = value();
    else if (flag == "--prefix") prefix = value();
    else if (flag == "--no-resume") resume = false;
    else if (!set_from_flag(opt, noisy_option_table(), flag.substr(2), value) &&
             !set_from_flag(opt.synthesis, synthesis_option_table(), flag.substr(2), value))
      throw ValueError(concat("unknown option '", flag, "' (see tempera noisy --help)"));
  }
  if (exemplar.empty()) throw ValueError("--exemplar is required (a sample of the medium)");
  if (reference.empty()) throw ValueError("--reference is required (the folder of coherent frames)");
  if (frames_text.empty()) throw ValueError("--frames is required (e.g. --frames 1-24)");
  if (out.empty()) throw ValueError("--out is required (the output folder)");
  validate_fields(opt, noisy_option_table());
  validate(opt.synthesis);
  if (fs::weakly_canonical(out) == fs::weakly_canonical(reference))
    throw ValueError("--out must not be the --reference folder (the frames would be overwritten)");
  const std::vector<int> frames = parse_frames(frames_text);
  const Image medium = read_image(exemplar);
  Image map;
  if (!noise_map.empty()) map = extract_channels(read_image(noise_map).view(), 0, 1);
  fs::create_directories(fs::path(out) / ".tempera_noisy");
  const std::string settings = settings_text(opt, noisy_option_table()) +
                               settings_text(opt.synthesis, synthesis_option_table()) + file_stamp(exemplar) +
                               (noise_map.empty() ? "" : file_stamp(noise_map));
  int made = 0, skipped = 0;
  for (int frame : frames) {
    const std::string input = (fs::path(reference) / frame_file(prefix, frame, "png")).string();
    if (!fs::is_regular_file(input)) throw FileNotFoundError(concat("reference frame not found: '", input, "'"));
    const fs::path output = fs::path(out) / frame_file(prefix, frame, "png");
    const fs::path key_file = fs::path(out) / ".tempera_noisy" / frame_file("", frame, "key");
    const std::string key = hash_hex(concat(settings, "|", frame, "|", file_stamp(input)));
    if (resume && fs::is_regular_file(output) && fs::is_regular_file(key_file) && read_text(key_file) == key) {
      ++skipped;
      continue;
    }
    const Image r_frame = read_image(input);
    const Image result = noisy_frame(medium.view(), r_frame.view(), frame, opt, map.empty() ? ImageView{} : map.view());
    write_image(output.string(), result.view());  // atomic
    write_text_atomically(key_file, key);
    ++made;
    std::cerr << "tempera noisy: frame " << frame << " -> " << output.string() << "\n";
  }
  std::cout << "tempera noisy: " << made << " frame(s) made, " << skipped << " current\n";
  return 0;
}

}  // namespace tempera::cli

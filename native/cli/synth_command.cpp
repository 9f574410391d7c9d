// `tempera synth`: guided synthesis on image files, with options that people
// who know ebsynth recognise.
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

#include "cli_args.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/engine/patch_usage.hpp"
#include "tempera/app/paths.hpp"
#include "tempera/engine/synthesis.hpp"
#include "tempera/app/text_file.hpp"

namespace tempera::cli {
namespace {

std::string synth_help() {
  return "usage: tempera synth --style S.png --guide SRC.png TGT.png [--weight W] ... --output OUT.png [options]\n"
         "\n"
         "Synthesizes OUT from the exemplar S where the guides agree (StyLit image analogies).\n"
         "A --weight applies to the --guide pair before it (default 1).\n"
         "\n"
         "inputs and outputs:\n"
         "  --style FILE            exemplar (A')\n"
         "  --guide SRC TGT         a guide pair: SRC has the size of the style, TGT of the output;\n"
         "                          FILE:LAYER takes one layer of a multilayer EXR, e.g. a guide cache\n"
         "                          frame: --guide ex/frame_0001.exr:LDE shot/frame_0012.exr:LDE\n"
         "  --weight W              weight of the preceding guide pair\n"
         "  --output FILE           result (B'); PNG/JPEG are clamped to [0,1], EXR/TIFF keep float\n"
         "  --source-mask FILE      exemplar pixels that may be copied (> 0.5)\n"
         "  --target-mask FILE      output pixels to synthesize (> 0.5)\n"
         "  --reference FILE        B' to start the coarsest level from (Color Me Noisy)\n"
         "  --stats FILE            write energies, timings and coverage as JSON\n"
         "  --quiet                 no progress on stderr\n"
         "\n"
         "engine options (lists are comma-separated):\n" +
         flags_help<SynthesisOptions>(synthesis_option_table());
}

struct GuideFiles {
  std::string source, target;
  float weight = 1.0f;
};

// "FILE" or "FILE:LAYER": a layer of a multilayer EXR, e.g. a guide of a
// guide cache frame ("frame_0001.exr:FULL"). A path that exists as written
// is always taken whole.
Image read_input(const std::string& spec) {
  const std::size_t colon = spec.rfind(':');
  std::error_code ec;
  if (colon == std::string::npos || std::filesystem::exists(spec, ec)) return read_image(spec);
  return read_image_layer(spec.substr(0, colon), spec.substr(colon + 1));
}

// First channel of a mask file.
Image read_mask(const std::string& path) { return extract_channels(read_input(path).view(), 0, 1); }

void write_stats(const std::string& path, const SynthesisResult& r, const SynthesisOptions& opt) {
  std::ostringstream out;
  out << "{\n  \"usage\": \"" << patch_usage_name(opt.usage) << "\",\n  \"seconds\": " << r.seconds
      << ",\n  \"source_coverage\": " << r.source_coverage << ",\n  \"guide_channels\": " << r.guide_channels
      << ",\n  \"kept_guide_variance\": " << r.kept_guide_variance << ",\n  \"levels\": [\n";
  for (std::size_t i = 0; i < r.levels.size(); ++i) {
    const auto& l = r.levels[i];
    out << "    {\"level\": " << l.level << ", \"width\": " << l.width << ", \"height\": " << l.height
        << ", \"search_seconds\": " << l.search_seconds << ", \"usage_seconds\": " << l.usage_seconds
        << ", \"vote_seconds\": " << l.vote_seconds << ", \"usage_rounds\": " << l.usage_rounds << ", \"energy\": [";
    for (std::size_t k = 0; k < l.energy.size(); ++k) out << (k ? ", " : "") << l.energy[k];
    out << "]}" << (i + 1 < r.levels.size() ? "," : "") << "\n";
  }
  out << "  ]\n}\n";
  write_text_atomically(path, out.str(), "the stats file");
}

}  // namespace

int run_synth(const Args& args) {
  ArgReader in(args, "synth");
  if (in.wants_help()) {
    std::cout << synth_help();
    return 0;
  }
  std::string style_path, output_path, stats_path, source_mask_path, target_mask_path, reference_path;
  std::vector<GuideFiles> guides;
  SynthesisOptions opt;
  bool quiet = false;
  while (in.more()) {
    const std::string flag = in.flag();
    if (flag == "--style") style_path = in.value(flag);
    else if (flag == "--guide") {
      GuideFiles g;
      g.source = in.value(flag);
      g.target = in.value(flag);
      guides.push_back(g);
    } else if (flag == "--weight") {
      if (guides.empty()) throw ValueError("--weight must follow a --guide pair");
      guides.back().weight = in.number<float>(flag);
    } else if (flag == "--output") output_path = in.value(flag);
    else if (flag == "--source-mask") source_mask_path = in.value(flag);
    else if (flag == "--target-mask") target_mask_path = in.value(flag);
    else if (flag == "--reference") reference_path = in.value(flag);
    else if (flag == "--stats") stats_path = in.value(flag);
    else if (flag == "--quiet") quiet = true;
    else if (!set_from_flag(opt, synthesis_option_table(), flag.substr(2), [&] { return in.value(flag); }))
      throw ValueError(concat("unknown option '", flag, "' (see tempera synth --help)"));
  }
  if (style_path.empty()) throw ValueError("--style is required");
  if (output_path.empty()) throw ValueError("--output is required");
  if (guides.empty()) throw ValueError("at least one --guide SRC TGT pair is required");
  {  // issue 18: an output that is an input would be destroyed (tempera/app/paths.hpp)
    std::vector<std::string> inputs = {style_path, source_mask_path, target_mask_path};
    for (const auto& g : guides) inputs.insert(inputs.end(), {g.source, g.target});
    refuse_output_on_inputs(output_path, inputs, "--output");
  }

  Image style = read_input(style_path);
  std::vector<Image> sources, targets;
  for (const auto& g : guides) {
    sources.push_back(read_input(g.source));
    targets.push_back(read_input(g.target));
  }
  SynthesisInput input;
  input.style = style.view();
  for (std::size_t i = 0; i < guides.size(); ++i) {
    if (sources[i].width() != style.width() || sources[i].height() != style.height())
      throw ValueError(concat("guide source '", guides[i].source, "' is ", sources[i].width(), "x",
                              sources[i].height(), " but the style '", style_path, "' is ", style.width(), "x",
                              style.height()));
    input.guides.add(guides[i].source, sources[i].view(), targets[i].view(), guides[i].weight);
  }
  // The decoded guides (floats, 8 of the still's 9 input images) are freed
  // as soon as the solver has projected them, the exemplar's first.
  input.exemplar_guides_read = [&] { sources.clear(); };
  input.guides_read = [&] { targets.clear(); };
  Image source_mask, target_mask, reference;
  if (!reference_path.empty()) input.reference = (reference = read_input(reference_path)).view();
  if (!source_mask_path.empty()) input.source_mask = (source_mask = read_mask(source_mask_path)).view();
  if (!target_mask_path.empty()) input.target_mask = (target_mask = read_mask(target_mask_path)).view();
  // And the rest once the solver has its pyramids (the style: 13 MB of the still's peak).
  input.inputs_read = [&] { style = source_mask = target_mask = reference = Image(); };

  int last_percent = -1;
  const SynthesisResult result = synthesize(input, opt, [&](double f) {
    const int percent = int(f * 100);
    if (!quiet && percent != last_percent) std::cerr << "\rtempera synth: " << percent << "%" << std::flush;
    last_percent = percent;
    return true;
  });
  if (!quiet) std::cerr << "\n";
  write_image(output_path, result.image.view());
  if (!stats_path.empty()) write_stats(stats_path, result, opt);
  if (!quiet)
    std::cerr << "tempera synth: wrote " << output_path << " (" << result.image.width() << "x"
              << result.image.height() << ", " << result.seconds << " s)\n";
  return 0;
}

}  // namespace tempera::cli

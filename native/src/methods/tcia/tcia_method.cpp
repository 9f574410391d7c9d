#include "tempera/methods/tcia/tcia_method.hpp"

#include "tempera/methods/tcia/tcia_job.hpp"

namespace tempera {
namespace {

std::pair<int, int> parse_segment(const std::string& text) {
  if (text.find(',') == std::string::npos) {
    const std::size_t dash = text.find('-', 1);
    if (dash != std::string::npos) {
      const int first = parse_number<int>(text.substr(0, dash), "--segment");
      const int last = parse_number<int>(text.substr(dash + 1), "--segment");
      if (first < last) return {first, last};
    }
  }
  throw ValueError(concat("--segment expects A-B (from one key to the next), got '", text, "'"));
}

// The core's config and the coherent method's options as `tempera stylize`
// takes them: the exemplar render's guides, the light-path guide weights,
// keys, layers, a farm task's segment, its option tables and the engine's
// (given in order, on the method's own engine defaults).
TciaJobConfig job_config(const JobConfig& given, const MethodOptions& options) {
  TciaJobConfig c;
  static_cast<JobConfig&>(c) = given;
  std::vector<std::pair<std::string, KeyFile>> layer_keys;
  for (const auto& [flag, text] : options) {
    if (flag == "exemplar-guides") c.exemplar_guides = text;
    else if (flag == "exemplar-frame") c.exemplar_frame = parse_number<int>(text, "--exemplar-frame");
    else if (flag == "weights") parse_guide_weights(text, c.weights);
    else if (flag == "key") c.keys.push_back(parse_key(text));
    else if (flag == "layer") c.layers.push_back(parse_layer(text));
    else if (flag == "layer-key") layer_keys.push_back(parse_layer_key(text));
    else if (flag == "layer-order") c.layer_order = text;
    else if (flag == "segment") c.segment = parse_segment(text);
    else if (!set_from_text(c.tcia, tcia_option_table(), flag, text) &&
             !set_from_text(c.lines, tcia_line_option_table(), flag, text) &&
             !set_from_text(c.orientation, tcia_orientation_option_table(), flag, text) &&
             !set_from_text(c.tcia.synthesis, synthesis_option_table(), flag, text))
      throw unknown_method_option("tcia", flag);
  }
  add_layer_keys(c.layers, layer_keys);
  return c;
}

// The coherent method's own flags.
std::string options_help() {
  return concat(
      "  --exemplar-guides DIR   guide cache of the exemplar render (or --exemplar-scene FILE)\n"
      "  --exemplar-frame N      frame of the exemplar (default: 1 with --exemplar-scene,\n"
      "                          else the only frame in --exemplar-guides)\n"
      "  --weights LIST          light-path guide weights, as StyLit's\n"
      "  --key F=PATH[,MASK]     a painted keyframe (repeatable); comes out as painted\n"
      "                          (where MASK > 0.5 if given) and steers its neighbours\n"
      "  --segment A-B           solve only the segment from key A to key B (a farm\n"
      "                          task); the shot splits at keys into independent segments\n"
      "  --layer NAME=MASK[,PAINTING]  a layer (repeatable), solved alone with its motion\n"
      "                          extrapolated past its outline (Benard 2013 Fig. 10): MASK is the\n"
      "                          guide cache's mask of its object or collection (mask.CO_Suit),\n"
      "                          PAINTING its own painting over the exemplar render (default: the\n"
      "                          shared one); frames RGBA in OUT/frames/layers/NAME/, composited\n"
      "                          into OUT/frames (the back-most layer fills what no mask covers)\n"
      "  --layer-key NAME:F=PATH[,MASK]  a key of layer NAME only (repeatable): at frame F it\n"
      "                          replaces the --key of that frame for the layer, so the layer's pixels\n"
      "                          of the composite come out as painted; segments split there too\n"
      "  --layer-order O         depth (default: per frame, by the guide cache's depth) | given\n"
      "                          (the --layer order, first at the back)\n",
      flags_help<TciaOptions>(tcia_option_table(), true), flags_help<TciaLineOptions>(tcia_line_option_table(), true),
      flags_help<TciaOrientationOptions>(tcia_orientation_option_table(), true),
      "  (any engine option of 'tempera synth --help'; the method's engine defaults: 9x9 Gaussian\n"
      "  window, centre output, histogram usage, automatic levels, --search-radius 64. Resume, Ctrl-C\n"
      "  and SIGTERM work per segment.)\n");
}

}  // namespace

MethodEntry tcia_method() {
  MethodEntry m;
  m.name = "tcia";
  m.title = "Temporally Coherent (Bénard 2013)";
  m.summary =
      "The whole shot at once, coarse to fine in forward and backward sweeps along the motion, so the paint "
      "stays on the surfaces; painted Keyframes come out as painted and steer the frames around them (Stylize "
      "Frame stays per-frame StyLit)";
  m.paper = "Bénard et al. 2013";
  m.unit = "segment";
  m.light_path_guides = true;
  m.default_exemplar = kKitExemplar;  // the painted sphere on a table
  m.docs = "docs/coherent.md";
  m.make_segment_job = [](const JobConfig& config, const MethodOptions& options) {
    return std::make_unique<TciaJob>(job_config(config, options));
  };
  m.check_options = [](const MethodOptions& options) { job_config({}, options); };
  m.options_help = options_help();
  return m;
}

}  // namespace tempera

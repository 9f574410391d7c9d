#include "tempera/methods/tcia/tcia_method.hpp"

#include "tempera/methods/tcia/tcia_job.hpp"

namespace tempera {
namespace {

// The coherent method's own flags (its command, cli/stylize_command.cpp,
// also takes StyLit's --weights, --temporal and the engine's).
std::string options_help() {
  return concat(
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
      flags_help<TciaOptions>(tcia_option_table()), flags_help<TciaLineOptions>(tcia_line_option_table()),
      flags_help<TciaOrientationOptions>(tcia_orientation_option_table()),
      "  tcia's engine defaults: 9x9 Gaussian window, centre output, histogram usage, automatic levels;\n"
      "  its --temporal defaults to 3. Resume, Ctrl-C and SIGTERM work per segment.\n");
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
  m.docs = "docs/coherent.md";
  m.options_help = options_help();
  return m;
}

}  // namespace tempera

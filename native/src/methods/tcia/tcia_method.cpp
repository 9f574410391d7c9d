#include "tempera/methods/tcia/tcia_method.hpp"

namespace tempera {

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
  return m;
}

}  // namespace tempera

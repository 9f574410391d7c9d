#include "tempera/methods/stylit/stylit_method.hpp"

namespace tempera {

MethodEntry stylit_method() {
  MethodEntry m;
  m.name = "stylit";
  m.title = "Per-Frame StyLit";
  m.summary =
      "Each frame painted on its own from the light-path guides (with the temporal guide's pull towards the "
      "previous frame); frames split anywhere over machines";
  m.paper = "Fišer et al. 2016";
  m.unit = "frame";
  m.light_path_guides = true;
  m.docs = "docs/user_guide.md";
  return m;
}

}  // namespace tempera

#include "tempera/methods/rigid/rigid_method.hpp"

namespace tempera {

MethodEntry rigid_method() {
  MethodEntry m;
  m.name = "rigid";
  m.title = "Rigid Bodies (hand-drawn)";
  m.summary =
      "The squash, stretch and line of drawn examples carried onto the scene's rigid-body simulation "
      "(Dvorožňák 2017; needs a baked rigid-body world)";
  m.paper = "Dvorožňák et al. 2017";
  m.unit = "frame";
  m.light_path_guides = false;
  m.docs = "docs/rigid_bodies.md";
  m.python_command = "tempera.methods.rigid.rigid_cli:stylize_main";
  return m;
}

}  // namespace tempera

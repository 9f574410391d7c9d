#include "tempera/methods/registry.hpp"

#include <algorithm>

#include "tempera/engine/error.hpp"
#include "tempera/methods/fluidymation/fluidymation_method.hpp"
#include "tempera/methods/lazyfluids/lazyfluids_method.hpp"

namespace tempera {

namespace {

std::deque<MethodEntry>& registry() {
  static std::deque<MethodEntry> registry = {
      {"stylit", "Per-Frame StyLit",
       "Each frame painted on its own from the light-path guides (with the temporal guide's pull towards the "
       "previous frame); frames split anywhere over machines",
       "Fišer et al. 2016", "frame", true, "docs/user_guide.md", ""},
      {"tcia", "Temporally Coherent (Bénard 2013)",
       "The whole shot at once, coarse to fine in forward and backward sweeps along the motion, so the paint stays "
       "on the surfaces; painted Keyframes come out as painted and steer the frames around them (Stylize Frame "
       "stays per-frame StyLit)",
       "Bénard et al. 2013", "segment", true, "docs/coherent.md", ""},
      {"rigid", "Rigid Bodies (hand-drawn)",
       "The squash, stretch and line of drawn examples carried onto the scene's rigid-body simulation "
       "(Dvorožňák 2017; needs a baked rigid-body world)",
       "Dvorožňák et al. 2017", "frame", false, "docs/rigid_bodies.md", "tempera.methods.rigid.rigid_cli:stylize_main"},
      lazyfluids_method(),
      fluidymation_method(),
  };
  return registry;
}

}  // namespace

const std::deque<MethodEntry>& method_registry() { return registry(); }

void register_method(MethodEntry entry) {
  const bool plain = !entry.name.empty() && std::all_of(entry.name.begin(), entry.name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
  if (!plain) throw ValueError(concat("a method's name is a plain lower-case word, got '", entry.name, "'"));
  for (const MethodEntry& m : registry())
    if (m.name == entry.name) throw ValueError(concat("the method '", entry.name, "' is registered already"));
  if (!entry.make_job && entry.python_command.empty())
    throw ValueError(concat("the method '", entry.name, "' has no job (make_job) to run"));
  registry().push_back(std::move(entry));
}

const MethodEntry& find_method(const std::string& name) {
  const auto& registry = method_registry();
  std::string choices;
  for (std::size_t i = 0; i < registry.size(); ++i) {
    if (registry[i].name == name) return registry[i];
    choices += concat(i == 0 ? "" : i + 1 == registry.size() ? " or " : ", ", registry[i].name);
  }
  throw ValueError(concat("unknown --method '", name, "' (choose ", choices, ")"));
}

}  // namespace tempera

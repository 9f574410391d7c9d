#include "tempera/methods/registry.hpp"

#include <algorithm>
#include <filesystem>

#include "tempera/engine/error.hpp"
#include "tempera/methods/fluidymation/fluidymation_method.hpp"
#include "tempera/methods/lazyfluids/lazyfluids_method.hpp"
#include "tempera/methods/noisy/noisy_method.hpp"
#include "tempera/methods/rigid/rigid_method.hpp"
#include "tempera/methods/stylit/stylit_method.hpp"
#include "tempera/methods/tcia/tcia_method.hpp"

namespace tempera {

namespace {

// Every built-in method, one line each, in the panel's order; each entry is
// written in its method's folder.
std::deque<MethodEntry>& registry() {
  static std::deque<MethodEntry> registry = {
      stylit_method(),
      tcia_method(),
      rigid_method(),
      lazyfluids_method(),
      fluidymation_method(),
      noisy_method(),
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
  const bool segments = entry.unit == "segment";
  if (!(segments ? bool(entry.make_segment_job) : bool(entry.make_job)))
    throw ValueError(concat("the method '", entry.name, "' has no job (", segments ? "make_segment_job" : "make_job",
                            ") to run"));
  registry().push_back(std::move(entry));
}

namespace {

// The other methods whose --help lists `--flag` ("tcia", "lazyfluids or
// fluidymation"), so that a flag given to the wrong method says which takes it.
std::string methods_taking(const std::string& flag, const std::string& except) {
  const std::string token = "  --" + flag;
  std::string names;
  for (const MethodEntry& m : method_registry()) {
    const std::string& help = m.options_help;
    for (std::size_t at = help.find(token); m.name != except && at != std::string::npos; at = help.find(token, at + 1)) {
      const std::size_t end = at + token.size();
      if (end == help.size() || help[end] == ' ' || help[end] == '\n') {
        names += concat(names.empty() ? "" : " or ", m.name);
        break;
      }
    }
  }
  return names;
}

}  // namespace

ValueError unknown_method_option(const std::string& name, const std::string& flag) {
  const std::string others = methods_taking(flag, name);
  return ValueError(concat("unknown option '--", flag, "' for --method ", name,
                           others.empty() ? "" : concat(": --", flag, " needs --method ", others),
                           " (see tempera stylize --method ", name, " --help)"));
}

const MethodEntry& default_method() { return method_registry().front(); }

const MethodEntry& find_method(const std::string& name) {
  const auto& registry = method_registry();
  std::string choices;
  for (std::size_t i = 0; i < registry.size(); ++i) {
    if (registry[i].name == name) return registry[i];
    choices += concat(i == 0 ? "" : i + 1 == registry.size() ? " or " : ", ", registry[i].name);
  }
  throw ValueError(concat("unknown --method '", name, "' (choose ", choices, ")"));
}

namespace {

// What a method without the asked kind of job runs by instead.
ValueError no_job_factory(const MethodEntry& method, const char* kind) {
  return ValueError(concat("--method ", method.name, " has no ", kind, " job factory: its unit is the ", method.unit,
                           " (", method.docs, ")"));
}

}  // namespace

std::unique_ptr<FrameJob> make_method_job(const MethodEntry& method, JobConfig config, const MethodOptions& options) {
  if (!method.make_job) throw no_job_factory(method, "frame");
  config.out = (std::filesystem::path(config.out) / "frames").string();
  return method.make_job(config, options);
}

std::unique_ptr<SegmentJob> make_method_segment_job(const MethodEntry& method, JobConfig config,
                                                    const MethodOptions& options) {
  if (!method.make_segment_job) throw no_job_factory(method, "segment");
  config.out = (std::filesystem::path(config.out) / "frames").string();
  return method.make_segment_job(config, options);
}

}  // namespace tempera

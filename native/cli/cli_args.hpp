#pragma once
// Small command-line reader shared by the `tempera` subcommands.
#include <charconv>
#include <csignal>
#include <string>
#include <vector>

#include "tempera/engine/error.hpp"
#include "tempera/methods/registry.hpp"

namespace tempera::cli {

using Args = std::vector<std::string>;

class ArgReader {
 public:
  ArgReader(const Args& args, std::string command) : args_(args), command_(std::move(command)) {}
  bool wants_help() const {
    for (const auto& a : args_)
      if (a == "--help" || a == "-h") return true;
    return false;
  }
  bool more() const { return pos_ < args_.size(); }
  std::string flag() {
    const std::string& f = args_[pos_++];
    if (f.rfind("--", 0) != 0) throw ValueError(concat("unexpected argument '", f, "'"));
    return f;
  }
  // The next argument if it is not a flag (an optional value), else null.
  const std::string* optional_value() const {
    return pos_ < args_.size() && args_[pos_].rfind("--", 0) != 0 ? &args_[pos_] : nullptr;
  }
  std::string value(const std::string& flag) {
    if (pos_ >= args_.size()) throw ValueError(concat(flag, " needs a value"));
    return args_[pos_++];
  }
  template <typename T>
  T number(const std::string& flag) {
    const std::string text = value(flag);
    T out{};
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
    if (ec != std::errc() || end != text.data() + text.size())
      throw ValueError(concat(flag, " expects a number, got '", text, "'"));
    return out;
  }

 private:
  const Args& args_;
  std::string command_;
  std::size_t pos_ = 0;
};

int run_synth(const Args& args);
int run_render_guides(const Args& args);
int run_stylize(const Args& args);
// `stylize --method NAME` for a method the registry runs by its job factory (method_command.cpp).
int run_registered_method(const MethodEntry& method, const Args& args);
// The method of `stylize` arguments: the last --method's value, else the registry's default_method().
// run_stylize sends the arguments to that method's command (methods/registry.hpp).
std::string method_of(const Args& args);

// Which Blender renders guides, and where it finds the tempera package.
struct BlenderSetup {
  std::string blender;  // $TEMPERA_BLENDER or "blender"
  std::string addon;    // $TEMPERA_ADDON_PATH or this build's addon folder
};
BlenderSetup default_blender_setup();

// Renders `scene`'s guide cache in background Blender with the add-on's
// renderer; `options` are render-guides options (--frames, --out, ...).
// Returns the exit status: 0, 2 (bad values), 1 (any other failure, said on stderr), 130. FileNotFoundError for a missing scene,
// Blender or package. Once the caller's signal handler sets *interrupted (SIGINT, SIGTERM), Blender is stopped too.
int render_guides_in_blender(const BlenderSetup& setup, const std::string& scene, const Args& options,
                             const volatile std::sig_atomic_t* interrupted);

// Sorted unique frames of "1-24" or "1-10,15" (ValueError naming the bad part).
std::vector<int> parse_frames(const std::string& text);

}  // namespace tempera::cli

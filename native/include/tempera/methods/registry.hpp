#pragma once
// The method registry (issue 41, step 4): every method of `tempera stylize
// --method`, named once. The command line's dispatch and its "unknown
// --method" message, the bindings' methods(), the panel's Method list
// (tempera/methods/registry.py), the `tempera` console script and the farm
// planner all read it; a new method adds one entry here (and its command).
// Color Me Noisy is not a method of this list: it is a pass over any
// method's frames (`--noise`, `tempera noisy`).
#include <string>
#include <vector>

namespace tempera {

struct MethodEntry {
  std::string name;     // --method NAME; the panel's item is NAME in capitals
  std::string title;    // the panel's Method list
  std::string summary;  // the panel's tooltip
  std::string paper;    // who described it
  // The unit of work, which the farm must not cut: "frame" (independent
  // frames, split anywhere), "segment" (key to key, one task each) or
  // "chained frame" (each frame made from the previous: one task).
  std::string unit;
  // StyLit's guide needs: the method matches a painting of an exemplar render
  // to the shot by light-path guides, so it takes the exemplar's guide cache
  // (--exemplar-guides or --exemplar-scene), --temporal, and writes a video.
  // The others take their exemplar as it is (an image, a video, drawings).
  bool light_path_guides = false;
  std::string docs;  // its page under docs/
  // Where it runs: "" for the native command; else the Python function that
  // runs `tempera stylize --method NAME ...` ("module:function").
  std::string python_command;
};

const std::vector<MethodEntry>& method_registry();

// The entry of `name`; ValueError "unknown --method 'X' (choose ...)" naming every one.
const MethodEntry& find_method(const std::string& name);

}  // namespace tempera

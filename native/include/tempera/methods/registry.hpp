#pragma once
// The method registry (issue 41, step 4): every method of `tempera stylize
// --method`, named once. The command line's dispatch and its "unknown
// --method" message, the bindings' methods(), the panel's Method list
// (tempera/methods/registry.py), the `tempera` console script and the farm
// planner all read it; a new method adds one entry in registry.cpp, with
// its job factory (make_job), and needs no command of its own
// (docs/adding_a_method.md). Color Me Noisy is both a method of this list
// (the render boiled, `--method noisy`) and a pass over a light-path
// method's frames (`--noise`); `tempera noisy` boils any folder of frames.
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "tempera/app/frame_job.hpp"
#include "tempera/app/job_config.hpp"
#include "tempera/app/segment_job.hpp"
#include "tempera/engine/error.hpp"

namespace tempera {

// A method's own options as the command line gives them: the flag without
// "--", and its text ("strength" -> "0.5"), in order.
using MethodOptions = std::vector<std::pair<std::string, std::string>>;

// The job of a method from the core's config (exemplar, guides, frames, out,
// format, resume; out is the frames' folder, OUT/frames: make_method_job) and its own options: ValueError naming a bad or unknown
// option, the errors of its inputs (files, sizes) as any job's.
using MakeJob = std::function<std::unique_ptr<FrameJob>(const JobConfig&, const MethodOptions&)>;
// The same for a method whose unit is the segment (app/segment_job.hpp).
using MakeSegmentJob = std::function<std::unique_ptr<SegmentJob>(const JobConfig&, const MethodOptions&)>;

// A MethodEntry's default_exemplar when its job makes the exemplar itself.
constexpr const char* kJobMadeExemplar = "generated";
// A MethodEntry's default_exemplar when it is the bundled exemplar kit: a
// painting and its exemplar render's guide cache (tempera/app/exemplar_kit.py),
// the light-path methods' stand-in for the artist's painting.
constexpr const char* kKitExemplar = "kit";

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
  // The job, which the registry's one command runs (cli/method_command.cpp:
  // flags, resume, progress, Ctrl-C, a .blend's guides, and for a
  // light-path method the exemplar scene, the video and the noise pass):
  // make_job for the units "frame" and "chained frame", make_segment_job for
  // "segment".
  MakeJob make_job;
  MakeSegmentJob make_segment_job;
  // Reads the method's options as its job factory does, touching no file:
  // ValueError naming an unknown option or a bad value. The command calls it
  // before Blender renders a scene's guides, so a typo costs no render.
  // Optional (the job factory checks them anyway).
  std::function<void(const MethodOptions&)> check_options;
  // Its own options, for --help: "  --strength S   ...\n" lines. Given alone
  // (no value), an option arrives with the text "" (set_from_text: a switch).
  std::string options_help;
  // The project's own exemplar that stands in when --exemplar is left out:
  // the kind `tempera exemplar KIND` writes ("smoke", "ink"), which the
  // Python package's `tempera stylize` generates into OUT once and passes
  // on (tempera/app/exemplar_cli.py); kJobMadeExemplar when the job makes its
  // own from an empty --exemplar (the rigid-body method's drawn ball);
  // kKitExemplar when the Python package passes the bundled kit's painting
  // and guides (the light-path methods); "" when the method needs the artist's.
  std::string default_exemplar;
  // More of --help, after the summary: what the exemplar and the guides must
  // hold, where the outputs go, how resume decides; paragraphs ending in "\n".
  std::string help_details;
};

// Every method, in the panel's order; a deque, so that entries keep their
// address when a method is registered.
const std::deque<MethodEntry>& method_registry();

// Adds a method at run time (a plug-in, a test's example): registered before
// a front end reads the registry, it is run like any other. ValueError when
// the name is empty, taken or not a plain word, or when it has no job
// factory for its unit. Not thread-safe: register at start-up.
void register_method(MethodEntry entry);

// The ValueError of an option that the method `name` does not take,
// pointing to its --help: what every job factory throws for one.
ValueError unknown_method_option(const std::string& name, const std::string& flag);

// The method when none is named (`tempera stylize` without --method, the
// panel's and the farm's default): the registry's first entry.
const MethodEntry& default_method();

// The entry of `name`; ValueError "unknown --method 'X' (choose ...)" naming every one.
const MethodEntry& find_method(const std::string& name);

// The job of `method` in the one output layout of every front end (the
// command, Python's make_job, the panel): its frames and records in
// OUT/frames, so that OUT holds what goes beside them (the contact sheet, a
// video, the generated exemplar, the guides). ValueError for a method
// without a job factory.
std::unique_ptr<FrameJob> make_method_job(const MethodEntry& method, JobConfig config, const MethodOptions& options);
// The same for a method whose unit is the segment.
std::unique_ptr<SegmentJob> make_method_segment_job(const MethodEntry& method, JobConfig config,
                                                    const MethodOptions& options);

}  // namespace tempera

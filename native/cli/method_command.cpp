// `tempera stylize --method NAME` for a method the registry runs by its job
// factory (methods/registry.hpp, make_job): one command for every such
// method, with the core's flags, resume, progress lines and Ctrl-C, so that
// a new method needs no command of its own (docs/adding_a_method.md).
#include <iomanip>
#include <iostream>

#include "cli_args.hpp"
#include "frame_loop.hpp"
#include "tempera/engine/error.hpp"

namespace tempera::cli {
namespace {

std::string method_help(const MethodEntry& m) {
  return concat("usage: tempera stylize --method ", m.name,
                " --guides DIR --exemplar PATH --frames A-B --out DIR [options]\n"
                "       tempera stylize SCENE.blend --method ",
                m.name, " --exemplar PATH --frames A-B --out DIR [--samples N] [options]\n\n", m.title, " (",
                m.paper, "): ", m.summary, ". See ", m.docs,
                ".\n\n"
                "inputs and outputs:\n"
                "  --exemplar PATH         the exemplar\n"
                "  --guides DIR            guide cache of the animation (with SCENE.blend: rendered there first,\n"
                "                          default OUT/guides)\n"
                "  --frames RANGE          frames to make, e.g. 1-24\n"
                "  --out DIR               output folder\n"
                "  --format F              png (default) | exr\n"
                "  --no-resume             make every frame again, even if current\n\n"
                "method options:\n",
                m.options_help.empty() ? "  (none)\n" : m.options_help,
                "\nExit status: 0 done, 1 error (files), 2 bad usage or bad values, 130 interrupted.\n");
}

}  // namespace

int run_registered_method(const MethodEntry& method, const Args& args) {
  if (ArgReader(args, "stylize").wants_help()) {
    std::cout << method_help(method);
    return 0;
  }
  JobConfig config;
  MethodOptions options;
  ArgReader r(args, "stylize");
  while (r.more()) {
    const std::string flag = r.flag();
    if (flag == "--method") r.value(flag);  // how we got here
    else if (flag == "--exemplar") config.exemplar = r.value(flag);
    else if (flag == "--guides") config.guides = r.value(flag);
    else if (flag == "--frames") config.frames = parse_frames(r.value(flag));
    else if (flag == "--out") config.out = r.value(flag);
    else if (flag == "--format") config.format = r.value(flag);
    else if (flag == "--no-resume") config.resume = false;
    else options.emplace_back(flag.substr(2), r.value(flag));  // the method's: it names the unknown ones
  }
  if (config.frames.empty()) throw ValueError("--frames is required (e.g. --frames 1-24)");
  if (config.out.empty()) throw ValueError("--out is required (the output folder)");
  catch_interrupts();
  const std::unique_ptr<FrameJob> job = method.make_job(config, options);
  for (const auto& w : job->warnings()) std::cerr << "tempera stylize: warning: " << w << "\n";
  std::vector<FrameResult> results;
  if (!run_frames(*job, results)) return report_interrupted("stylize");
  const FrameTally t = tally(results);
  std::cout << "tempera stylize: " << t.made << " frame(s) stylized, " << t.skipped
            << " skipped (already current) in " << std::fixed << std::setprecision(1) << t.seconds << " s"
            << std::defaultfloat << "; results in " << config.out << "\n";
  return 0;
}

}  // namespace tempera::cli

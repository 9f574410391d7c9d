// `tempera stylize --method NAME` for a method the registry runs by its job
// factory (methods/registry.hpp, make_job): one command for every such
// method, built in or a plug-in, with the core's flags,
// resume, progress lines, Ctrl-C and contact sheet, so that a method needs
// no command of its own (docs/adding_a_method.md).
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "cli_args.hpp"
#include "frame_loop.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/engine/error.hpp"

namespace fs = std::filesystem;

namespace tempera::cli {
namespace {

// The help's note on the default exemplar, if the method has one.
std::string method_default_exemplar(const MethodEntry& m) {
  if (m.default_exemplar.empty()) return "";
  return concat(" (left out: the Python package's tempera generates\n"
                "                          the project's own ", m.default_exemplar, " into OUT/exemplar_generated_",
                m.default_exemplar, ")");
}

std::string method_help(const MethodEntry& m) {
  return concat("usage: tempera stylize --method ", m.name,
                " --guides DIR --exemplar PATH --frames A-B --out DIR [options]\n"
                "       tempera stylize SCENE.blend --method ",
                m.name, " --exemplar PATH --frames A-B --out DIR [--samples N] [options]\n\n", m.title, " (",
                m.paper, "): ", m.summary, ". See ", m.docs, ".\n\n", m.help_details,
                m.help_details.empty() ? "" : "\n",
                "inputs and outputs:\n"
                "  --exemplar PATH         the exemplar",
                method_default_exemplar(m), "\n"
                "  --guides DIR            guide cache of the animation (with SCENE.blend: rendered there first\n"
                "                          by background Blender, default OUT/guides, as tempera render-guides\n"
                "                          does: --samples N, --blender PATH, --addon-path DIR)\n"
                "  --frames RANGE          frames to make, e.g. 1-24\n"
                "  --out DIR               output folder\n"
                "  --format F              png (default) | exr\n"
                "  --no-resume             make every frame again, even if current\n"
                "  --max-image-pixels N    refuse images declaring more pixels (default 50000000)\n\n"
                "method options:\n",
                m.options_help.empty() ? "  (none)\n" : m.options_help,
                "\nExit status: 0 done, 1 error (files), 2 bad usage or bad values, 130 interrupted.\n");
}

// The core's flags into `config`; every other flag is the method's, with its
// text, or "" when it stands alone (a switch).
MethodOptions parse(const MethodEntry& method, const Args& args, JobConfig& config) {
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
    else if (flag == "--max-image-pixels") set_max_image_pixels(r.number<std::int64_t>(flag));
    else options.emplace_back(flag.substr(2), r.optional_value() ? r.value(flag) : "");  // the method names unknown ones
  }
  if (config.exemplar.empty() && !method.default_exemplar.empty())
    throw ValueError(concat("--exemplar is required here; the Python package's 'tempera stylize' uses the project's "
                            "own ", method.default_exemplar, " exemplar when it is left out (or write it with "
                            "'tempera exemplar ", method.default_exemplar, " --out DIR')"));
  for (const auto& [value, what] : {std::pair{&config.exemplar, "--exemplar is required (the exemplar)"},
                                    {&config.guides, "--guides is required (the shot's guide cache)"},
                                    {&config.out, "--out is required (the output folder)"}})
    if (value->empty()) throw ValueError(what);
  if (config.frames.empty()) throw ValueError("--frames is required (e.g. --frames 1-24)");
  return options;
}

}  // namespace

int run_registered_method(const MethodEntry& method, const Args& args) {
  if (ArgReader(args, "stylize").wants_help()) {
    std::cout << method_help(method);
    return 0;
  }
  JobConfig config;
  const MethodOptions options = parse(method, args, config);  // usage errors: exit status 2
  catch_interrupts();
  const std::unique_ptr<FrameJob> job = make_method_job(method, config, options);  // frames in OUT/frames
  job->inputs().refuse_folder(config.out);  // the contact sheet goes there too
  for (const auto& w : job->warnings()) std::cerr << "tempera stylize: warning: " << w << "\n";
  FrameLine line;
  line.details = [](std::ostream& out, const FrameResult& r) {
    if (r.status != "skipped" && r.source_coverage > 0) out << ", source coverage " << r.source_coverage;
  };
  std::vector<FrameResult> results;
  if (!run_frames(*job, results, line)) return report_interrupted("stylize");
  const FrameTally t = tally(results);
  const std::string summary = job->summary();
  std::cout << "tempera stylize: " << t.made << " frame(s) stylized, " << t.skipped
            << " skipped (already current) in " << std::fixed << std::setprecision(1) << t.seconds << " s"
            << std::defaultfloat << (summary.empty() ? "" : "; ") << summary << "; results in " << config.out << "\n";
  const fs::path sheet = fs::path(config.out) / "contact_sheet.png";
  if (job->has_contact_sheet() &&
      write_beside_frames("stylize", "the contact sheet", [&] { job->write_contact_sheet(sheet.string()); }))
    std::cout << "contact sheet: " << sheet.string() << "\n";
  return 0;
}

}  // namespace tempera::cli

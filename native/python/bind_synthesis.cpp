// Python binding of the synthesis engine. Arrays stay owned by Python (held
// here for the whole call) and are viewed in place; the GIL is released while
// the engine runs and re-taken only to report progress.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <optional>

#include "numpy_bridge.hpp"
#include "tempera/synthesis.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

struct GuideArg {
  std::string name;
  FloatArray source, target;
  float weight;
  std::optional<FloatArray> target_weight_map;
};

ImageView optional_view(const std::optional<FloatArray>& array, const char* what) {
  return array ? py_bridge::view_of(*array, what) : ImageView{};
}

py::dict level_stats(const LevelStats& s) {
  py::dict d;
  d["level"] = s.level;
  d["width"] = s.width;
  d["height"] = s.height;
  d["energy"] = s.energy;
  d["search_seconds"] = s.search_seconds;
  d["usage_seconds"] = s.usage_seconds;
  d["vote_seconds"] = s.vote_seconds;
  d["usage_rounds"] = s.usage_rounds;
  d["reversed_coverage"] = s.reversed_coverage;
  return d;
}

py::array_t<std::int32_t> nnf_array(const Nnf& nnf) {
  py::array_t<std::int32_t> out({py::ssize_t(nnf.height), py::ssize_t(nnf.width), py::ssize_t(2)});
  auto v = out.mutable_unchecked<3>();
  for (int y = 0; y < nnf.height; ++y)
    for (int x = 0; x < nnf.width; ++x) {
      v(y, x, 0) = nnf.x[nnf.index(x, y)];
      v(y, x, 1) = nnf.y[nnf.index(x, y)];
    }
  return out;
}

py::tuple synthesize_py(const FloatArray& style, const std::vector<GuideArg>& guides, const std::string& usage,
                        int patch_size, int levels, int em_iterations, int pm_iterations, float style_weight,
                        float penalty_weight, double guide_variance, double budget_coverage, int budget_max_rounds,
                        std::uint64_t seed, int threads, const std::optional<FloatArray>& source_mask,
                        const std::optional<FloatArray>& target_mask,
                        const std::optional<FloatArray>& source_orientation,
                        const std::optional<FloatArray>& target_orientation,
                        const std::optional<FloatArray>& source_segments,
                        const std::optional<FloatArray>& target_segments,
                        std::optional<std::pair<int, int>> target_shape,
                        const std::function<bool(double)>& progress) {
  SynthesisInput in;
  in.style = py_bridge::view_of(style, "style");
  for (const auto& g : guides) {
    in.guides.add(g.name, py_bridge::view_of(g.source, "guide '" + g.name + "' source"),
                  py_bridge::view_of(g.target, "guide '" + g.name + "' target"), g.weight);
    in.target_weight_maps.push_back(optional_view(g.target_weight_map, "target weight map"));
  }
  in.source_mask = optional_view(source_mask, "source mask");
  in.target_mask = optional_view(target_mask, "target mask");
  in.source_orientation = optional_view(source_orientation, "source orientation");
  in.target_orientation = optional_view(target_orientation, "target orientation");
  in.source_segments = optional_view(source_segments, "source segments");
  in.target_segments = optional_view(target_segments, "target segments");
  if (target_shape) {
    in.target_height = target_shape->first;
    in.target_width = target_shape->second;
  }
  SynthesisOptions opt;
  opt.usage = parse_patch_usage(usage);
  opt.patch_size = patch_size;
  opt.levels = levels;
  opt.em_iterations = em_iterations;
  opt.pm_iterations = pm_iterations;
  opt.style_weight = style_weight;
  opt.penalty_weight = penalty_weight;
  opt.guide_variance = guide_variance;
  opt.budget_coverage = budget_coverage;
  opt.budget_max_rounds = budget_max_rounds;
  opt.seed = seed;
  opt.threads = threads;

  ProgressCallback callback = [&](double fraction) {
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C
    return progress ? progress(fraction) : true;
  };
  SynthesisResult result;
  {
    py::gil_scoped_release release;
    result = synthesize(in, opt, callback);
  }
  py::dict stats;
  py::list lv;
  for (const auto& s : result.levels) lv.append(level_stats(s));
  stats["levels"] = lv;
  stats["seconds"] = result.seconds;
  stats["source_coverage"] = result.source_coverage;
  stats["usage"] = usage;
  stats["guide_channels"] = result.guide_channels;
  stats["kept_guide_variance"] = result.kept_guide_variance;
  stats["nnf"] = nnf_array(result.nnf);
  return py::make_tuple(py_bridge::to_numpy(std::move(result.image)), stats);
}

}  // namespace

void bind_synthesis(py::module_& m) {
  m.def(
      "synthesize",
      [](const FloatArray& style, const py::list& guides, const std::string& usage, int patch_size, int levels,
         int em_iterations, int pm_iterations, float style_weight, float penalty_weight, double guide_variance,
         double budget_coverage,
         int budget_max_rounds, std::uint64_t seed, int threads, std::optional<FloatArray> source_mask,
         std::optional<FloatArray> target_mask, std::optional<FloatArray> source_orientation,
         std::optional<FloatArray> target_orientation, std::optional<FloatArray> source_segments,
         std::optional<FloatArray> target_segments, std::optional<std::pair<int, int>> target_shape,
         std::function<bool(double)> progress) {
        std::vector<GuideArg> parsed;
        for (const auto& item : guides) {
          auto t = item.cast<py::tuple>();
          if (t.size() != 5) throw ValueError("internal: guides must be (name, source, target, weight, map)");
          GuideArg g{t[0].cast<std::string>(), t[1].cast<FloatArray>(), t[2].cast<FloatArray>(),
                     t[3].cast<float>(), std::nullopt};
          if (!t[4].is_none()) g.target_weight_map = t[4].cast<FloatArray>();
          parsed.push_back(std::move(g));
        }
        return synthesize_py(style, parsed, usage, patch_size, levels, em_iterations, pm_iterations, style_weight,
                             penalty_weight, guide_variance, budget_coverage, budget_max_rounds, seed, threads, source_mask,
                             target_mask, source_orientation, target_orientation, source_segments, target_segments,
                             target_shape, progress);
      },
      py::arg("style"), py::arg("guides"), py::arg("usage"), py::arg("patch_size"), py::arg("levels"),
      py::arg("em_iterations"), py::arg("pm_iterations"), py::arg("style_weight"), py::arg("penalty_weight"),
      py::arg("guide_variance"), py::arg("budget_coverage"), py::arg("budget_max_rounds"), py::arg("seed"), py::arg("threads"),
      py::arg("source_mask"), py::arg("target_mask"), py::arg("source_orientation"), py::arg("target_orientation"),
      py::arg("source_segments"), py::arg("target_segments"), py::arg("target_shape"), py::arg("progress"),
      "Low-level engine entry; use tempera.synthesize().");
  m.def("error_knee", [](std::vector<float> sorted_errors) {
    std::sort(sorted_errors.begin(), sorted_errors.end());
    return error_knee(sorted_errors);
  }, py::arg("errors"), "Knee index of the sorted error curve (StyLit's error budget).");
}

// Python binding of the synthesis engine. Arrays stay owned by Python (held
// here for the whole call) and are viewed in place; the GIL is released while
// the engine runs and re-taken only to report progress.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <map>
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

// Engine options from a dict of Python values; unknown keys are errors so a
// typo never silently falls back to a default.
SynthesisOptions parse_options(const py::dict& options) {
  SynthesisOptions opt;
  for (const auto& [key_obj, value] : options) {
    const std::string key = key_obj.cast<std::string>();
    if (key == "usage") opt.usage = parse_patch_usage(value.cast<std::string>());
    else if (key == "patch_size") opt.patch_size = value.cast<int>();
    else if (key == "levels") opt.levels = value.cast<int>();
    else if (key == "em_iterations") opt.em_iterations = value.cast<int>();
    else if (key == "pm_iterations") opt.pm_iterations = value.cast<int>();
    else if (key == "style_weight") opt.style_weight = value.cast<float>();
    else if (key == "penalty_weight") opt.penalty_weight = value.cast<float>();
    else if (key == "guide_variance") opt.guide_variance = value.cast<double>();
    else if (key == "axial_orientation") opt.axial_orientation = value.cast<bool>();
    else if (key == "budget_coverage") opt.budget_coverage = value.cast<double>();
    else if (key == "budget_max_rounds") opt.budget_max_rounds = value.cast<int>();
    else if (key == "seed") opt.seed = value.cast<std::uint64_t>();
    else if (key == "threads") opt.threads = value.cast<int>();
    else throw ValueError(concat("unknown synthesis option '", key, "'"));
  }
  return opt;
}

py::tuple synthesize_py(const FloatArray& style, const std::vector<GuideArg>& guides, const py::dict& options,
                        const std::map<std::string, FloatArray>& maps,
                        std::optional<std::pair<int, int>> target_shape,
                        const std::function<bool(double)>& progress) {
  SynthesisInput in;
  in.style = py_bridge::view_of(style, "style");
  for (const auto& g : guides) {
    in.guides.add(g.name, py_bridge::view_of(g.source, "guide '" + g.name + "' source"),
                  py_bridge::view_of(g.target, "guide '" + g.name + "' target"), g.weight);
    in.target_weight_maps.push_back(optional_view(g.target_weight_map, "target weight map"));
  }
  const std::map<std::string, ImageView*> slots = {
      {"source_mask", &in.source_mask},
      {"target_mask", &in.target_mask},
      {"source_orientation", &in.source_orientation},
      {"target_orientation", &in.target_orientation},
      {"source_segments", &in.source_segments},
      {"target_segments", &in.target_segments},
  };
  for (const auto& [name, array] : maps) {
    auto slot = slots.find(name);
    if (slot == slots.end()) throw ValueError(concat("unknown map '", name, "'"));
    std::string what = name;
    std::replace(what.begin(), what.end(), '_', ' ');
    *slot->second = py_bridge::view_of(array, what);
  }
  if (target_shape) {
    in.target_height = target_shape->first;
    in.target_width = target_shape->second;
  }
  const SynthesisOptions opt = parse_options(options);

  ProgressCallback callback = py_bridge::with_gil([&](double fraction) {
    return progress ? progress(fraction) : true;
  });
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
  stats["usage"] = patch_usage_name(opt.usage);
  stats["guide_channels"] = result.guide_channels;
  stats["kept_guide_variance"] = result.kept_guide_variance;
  stats["nnf"] = nnf_array(result.nnf);
  return py::make_tuple(py_bridge::to_numpy(std::move(result.image)), stats);
}

}  // namespace

void bind_synthesis(py::module_& m) {
  m.def(
      "synthesize",
      [](const FloatArray& style, const py::list& guides, const py::dict& options,
         const std::map<std::string, FloatArray>& maps, std::optional<std::pair<int, int>> target_shape,
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
        return synthesize_py(style, parsed, options, maps, target_shape, progress);
      },
      py::arg("style"), py::arg("guides"), py::arg("options"), py::arg("maps"), py::arg("target_shape"),
      py::arg("progress"), "Low-level engine entry; use tempera.synthesize().");
  m.def("error_knee", [](std::vector<float> sorted_errors) {
    std::sort(sorted_errors.begin(), sorted_errors.end());
    return error_knee(sorted_errors);
  }, py::arg("errors"), "Knee index of the sorted error curve (StyLit's error budget).");
}

// Python binding of the synthesis engine. Arrays stay owned by Python (held
// here for the whole call) and are viewed in place; the GIL is released while
// the engine runs and re-taken only to report progress. Options and results
// are classes bound from their tables (bind_options.hpp).
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <map>
#include <optional>

#include "bind_options.hpp"
#include "numpy_bridge.hpp"
#include "tempera/engine/patch_usage.hpp"
#include "tempera/engine/pyramid.hpp"
#include "tempera/engine/synthesis.hpp"

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

// What synthesize() returns besides the image.
struct SynthesisStats {
  std::vector<LevelStats> levels;
  double seconds = 0, source_coverage = 0, kept_guide_variance = 1;
  int guide_channels = 0;
  std::string usage;
  py::array nnf;       // (H, W, 2) int32: integer source x, y in the matched exemplar's pixels
  py::array exemplar;  // (H, W) int32: 0 = style, k = exemplars[k - 1]
  py::array field;     // (H, W, 2) float32: sub-pixel source position
};

void fill_matches(const SynthesisResult& r, SynthesisStats& s) {
  const auto h = py::ssize_t(r.field.height), w = py::ssize_t(r.field.width);
  py::array_t<std::int32_t> nnf({h, w, py::ssize_t(2)}), ex({h, w});
  py::array_t<float> pos({h, w, py::ssize_t(2)});
  auto n = nnf.mutable_unchecked<3>();
  auto e = ex.mutable_unchecked<2>();
  auto p = pos.mutable_unchecked<3>();
  for (int y = 0; y < r.field.height; ++y)
    for (int x = 0; x < r.field.width; ++x) {
      const std::size_t i = r.field.index(x, y);
      const int src = r.layout.source_at(std::clamp(r.field.y[i], 0, r.layout.height - 1));
      e(y, x) = src;
      n(y, x, 0) = r.field.x[i];
      n(y, x, 1) = r.field.y[i] - r.layout.rects[std::size_t(src)].y0;
      p(y, x, 0) = r.field.position_x(i);
      p(y, x, 1) = r.field.position_y(i) - float(r.layout.rects[std::size_t(src)].y0);
    }
  s.nnf = nnf;
  s.exemplar = ex;
  s.field = pos;
}

ImageView optional_view(const py::object& array, const std::string& what, std::vector<FloatArray>& keep) {
  if (array.is_none()) return {};
  keep.push_back(array.cast<FloatArray>());
  return py_bridge::view_of(keep.back(), what);
}

// An exemplar from a dict: style, guides (list, in layer order), mask,
// orientation, segments, sequence, time.
Exemplar exemplar_from(const py::dict& d, std::size_t k, std::vector<FloatArray>& keep) {
  static const char* keys[] = {"style", "guides", "mask", "orientation", "segments", "sequence", "time"};
  for (const auto& [key, value] : d) {
    const std::string name = py::str(key);
    if (std::find(std::begin(keys), std::end(keys), name) == std::end(keys))
      throw ValueError(concat("exemplar ", k, ": unknown key '", name, "'"));
  }
  if (!d.contains("style")) throw ValueError(concat("exemplar ", k, " needs 'style'"));
  Exemplar e;
  const std::string what = concat("exemplar ", k);
  e.style = optional_view(d["style"], what, keep);
  if (d.contains("guides"))
    for (const auto& g : d["guides"].cast<py::list>()) e.guides.push_back(optional_view(py::reinterpret_borrow<py::object>(g), what + " guide", keep));
  auto get = [&](const char* key) { return d.contains(key) ? py::object(d[key]) : py::object(py::none()); };
  e.mask = optional_view(get("mask"), what + " mask", keep);
  e.orientation = optional_view(get("orientation"), what + " orientation", keep);
  e.segments = optional_view(get("segments"), what + " segments", keep);
  if (d.contains("sequence")) e.sequence = d["sequence"].cast<int>();
  if (d.contains("time")) e.time = d["time"].cast<int>();
  return e;
}

py::tuple synthesize_py(const FloatArray& style, const py::list& guides, const py::object& options,
                        const py::dict& maps, std::optional<std::pair<int, int>> target_shape,
                        const py::object& exemplars, const py::object& reference, const py::object& fixed,
                        const std::function<bool(double)>& progress) {
  SynthesisOptions opt;
  if (py::isinstance<py::dict>(options))
    py_bridge::set_from_dict(opt, synthesis_option_table(), options.cast<py::dict>(), "synthesis option");
  else
    opt = options.cast<SynthesisOptions>();
  std::vector<FloatArray> keep;
  SynthesisInput in;
  in.style = py_bridge::view_of(style, "style");
  for (const auto& item : guides) {
    auto t = item.cast<py::tuple>();
    if (t.size() != 5) throw ValueError("internal: guides must be (name, source, target, weight, map)");
    const std::string name = t[0].cast<std::string>();
    const ImageView src = optional_view(t[1], "guide '" + name + "' source", keep);
    const ImageView tgt = optional_view(t[2], "guide '" + name + "' target", keep);
    in.guides.add(name, src, tgt, t[3].cast<float>());
    in.target_weight_maps.push_back(optional_view(t[4], "target weight map", keep));
  }
  const std::map<std::string, ImageView*> slots = {
      {"source_mask", &in.source_mask},
      {"target_mask", &in.target_mask},
      {"source_orientation", &in.source_orientation},
      {"target_orientation", &in.target_orientation},
      {"source_segments", &in.source_segments},
      {"target_segments", &in.target_segments},
  };
  for (const auto& [key, array] : maps) {
    const std::string name = py::str(key);
    auto slot = slots.find(name);
    if (slot == slots.end()) throw ValueError(concat("unknown map '", name, "'"));
    std::string what = name;
    std::replace(what.begin(), what.end(), '_', ' ');
    *slot->second = optional_view(py::reinterpret_borrow<py::object>(array), what, keep);
  }
  if (target_shape) {
    in.target_height = target_shape->first;
    in.target_width = target_shape->second;
  }
  std::size_t k = 1;
  if (!exemplars.is_none())
    for (const auto& e : exemplars.cast<py::list>()) in.exemplars.push_back(exemplar_from(e.cast<py::dict>(), k++, keep));
  in.reference = optional_view(reference, "reference", keep);
  if (!fixed.is_none()) {
    const py::dict f = fixed.cast<py::dict>();
    for (const auto& [key, value] : f) {
      const std::string name = py::str(key);
      if (name != "mask" && name != "values" && name != "matches")
        throw ValueError(concat("fixed: unknown key '", name, "' (mask, values, matches)"));
    }
    auto get = [&](const char* key) { return f.contains(key) ? py::object(f[key]) : py::object(py::none()); };
    in.fixed.mask = optional_view(get("mask"), "fixed-pixel mask", keep);
    in.fixed.values = optional_view(get("values"), "fixed-pixel values", keep);
    in.fixed.matches = optional_view(get("matches"), "fixed-pixel matches", keep);
    if (in.fixed.mask.empty()) throw ValueError("fixed pixels need a 'mask'");
  }
  ProgressCallback callback = py_bridge::with_gil([&](double fraction) {
    return progress ? progress(fraction) : true;
  });
  SynthesisResult result;
  {
    py::gil_scoped_release release;
    result = synthesize(in, opt, callback);
  }
  SynthesisStats stats;
  stats.levels = result.levels;
  stats.seconds = result.seconds;
  stats.source_coverage = result.source_coverage;
  stats.usage = patch_usage_name(opt.usage);
  stats.guide_channels = result.guide_channels;
  stats.kept_guide_variance = result.kept_guide_variance;
  fill_matches(result, stats);
  return py::make_tuple(py_bridge::to_numpy(std::move(result.image)), stats);
}

// obj["name"] as obj.name, so results read like the dicts they replaced.
template <class C>
void add_item_access(C& cls) {
  cls.def("__getitem__", [](const py::object& self, const std::string& key) {
    if (!py::hasattr(self, key.c_str())) throw py::key_error(key);
    return self.attr(key.c_str());
  });
}

}  // namespace

void bind_synthesis(py::module_& m) {
  m.def(
      "box_blur",
      [](const FloatArray& image, float width) {
        const ImageView v = py_bridge::view_of(image, "image");
        Image out;
        {
          py::gil_scoped_release release;
          out = box_blur(v, width);
        }
        return py_bridge::to_numpy(std::move(out));
      },
      py::arg("image"), py::arg("width"), "Box low-pass of `width` pixels (pyramid.hpp), clamped at the borders.");
  py_bridge::bind_options_class<SynthesisOptions>(m, "SynthesisOptions", synthesis_option_table(),
                                                  "Options of the synthesis engine (native/include/tempera/engine/synthesis_options.hpp).")
      .def("validate", [](const SynthesisOptions& o) { validate(o); }, "ValueError naming the first bad option.");
  py::class_<LevelStats> level(m, "LevelStats", "Statistics of one pyramid level.");
  level.def_readonly("level", &LevelStats::level)
      .def_readonly("width", &LevelStats::width)
      .def_readonly("height", &LevelStats::height)
      .def_readonly("energy", &LevelStats::energy, "mean patch distance after each search")
      .def_readonly("search_seconds", &LevelStats::search_seconds)
      .def_readonly("usage_seconds", &LevelStats::usage_seconds)
      .def_readonly("vote_seconds", &LevelStats::vote_seconds)
      .def_readonly("usage_rounds", &LevelStats::usage_rounds)
      .def_readonly("usage_wide_searches", &LevelStats::usage_wide_searches)
      .def_readonly("converged_skips", &LevelStats::converged_skips)
      .def_readonly("reversed_coverage", &LevelStats::reversed_coverage)
      .def_readonly("source_coverage", &LevelStats::source_coverage);
  add_item_access(level);
  py::class_<SynthesisStats> stats(m, "SynthesisStats", "What synthesize() reports besides the image.");
  stats.def_readonly("levels", &SynthesisStats::levels, "per level, coarsest first")
      .def_readonly("seconds", &SynthesisStats::seconds)
      .def_readonly("source_coverage", &SynthesisStats::source_coverage)
      .def_readonly("kept_guide_variance", &SynthesisStats::kept_guide_variance)
      .def_readonly("guide_channels", &SynthesisStats::guide_channels)
      .def_readonly("usage", &SynthesisStats::usage)
      .def_readonly("nnf", &SynthesisStats::nnf, "(H, W, 2) int32 source x, y in the matched exemplar")
      .def_readonly("exemplar", &SynthesisStats::exemplar, "(H, W) int32 matched exemplar: 0 = style")
      .def_readonly("field", &SynthesisStats::field, "(H, W, 2) float32 sub-pixel source positions");
  add_item_access(stats);
  m.def("synthesize", &synthesize_py, py::arg("style"), py::arg("guides"), py::arg("options"), py::arg("maps"),
        py::arg("target_shape"), py::arg("exemplars") = py::none(), py::arg("reference") = py::none(),
        py::arg("fixed") = py::none(), py::arg("progress") = nullptr,
        "Low-level engine entry; use tempera.synthesize().");
  m.def("error_knee", [](std::vector<float> sorted_errors) {
    std::sort(sorted_errors.begin(), sorted_errors.end());
    return error_knee(sorted_errors);
  }, py::arg("errors"), "Knee index of the sorted error curve (StyLit's error budget).");
}

// Python binding of StyLit's options (StylitOptions), per frame and of the
// sequence driver (StylizeJob), plus its flicker measure; the job's config is StylizeJobConfig, bound field by
// field. tempera.methods.stylit.stylize wraps these with keyword arguments.
// The GIL is released while native code runs.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <cmath>
#include <set>

#include "bind_method.hpp"
#include "bind_frame_job.hpp"
#include "bind_frame_stats.hpp"
#include "bind_job_config.hpp"
#include "bind_options.hpp"
#include "numpy_bridge.hpp"
#include "tempera/methods/stylit/stylit.hpp"
#include "tempera/methods/stylit/stylize_job.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

void reject_unknown(const py::dict& d, const std::set<std::string>& known, const char* what) {
  std::string unknown;
  for (const auto& [key, value] : d) {
    const std::string k = py::str(key);
    if (!known.count(k)) unknown += (unknown.empty() ? "'" : ", '") + k + "'";
  }
  if (!unknown.empty()) throw ValueError(concat("unknown ", what, " key(s) ", unknown));
}

// The options' errors now, not in the middle of a run.
const StylitOptions& checked(const StylitOptions& opt) {
  validate(opt.synthesis);
  active_guides(opt);
  return opt;
}

StylizeJobConfig job_config(const StylizeJobConfig& config, const StylitOptions& options) {
  const std::string what = "StylizeJob config";
  py_bridge::require_light_path_shot(config, what);
  if (config.guides.empty()) throw ValueError(what + " needs 'guides'");
  StylizeJobConfig c = config;
  c.stylit = checked(options);
  return c;
}

// Arrays stay referenced by `keep` while the frame views them.
GuideFrame guide_frame(const py::dict& arrays, const char* what, std::vector<FloatArray>& keep) {
  GuideFrame frame;
  frame.origin = what;
  for (const auto& [key, value] : arrays) {
    const std::string name = py::str(key);
    keep.push_back(value.cast<FloatArray>());
    frame.guides[name] = Image::copy_of(py_bridge::view_of(keep.back(), concat(what, " guide '", name, "'")));
  }
  return frame;
}

py::tuple stylize_frame_py(const FloatArray& style, const py::dict& exemplar, const py::dict& target,
                           const StylitOptions& options, const py::object& temporal, const py::object& progress) {
  const StylitOptions& opt = checked(options);
  std::vector<FloatArray> keep;
  const GuideFrame ex = guide_frame(exemplar, "exemplar", keep), tg = guide_frame(target, "target", keep);
  TemporalInput t;
  OffsetField previous_field;
  const bool has_temporal = !temporal.is_none();
  if (has_temporal) {
    const py::dict d = temporal.cast<py::dict>();
    reject_unknown(d, {"previous", "velocity_backward", "occlusion_backward", "previous_field"}, "temporal");
    for (const char* key : {"velocity_backward", "occlusion_backward"})
      if (!d.contains(key)) throw ValueError(concat("temporal needs '", key, "'"));
    auto view = [&](const char* key) {
      keep.push_back(d[key].cast<FloatArray>());
      return py_bridge::view_of(keep.back(), key);
    };
    t.velocity_backward = view("velocity_backward");
    t.occlusion_backward = view("occlusion_backward");
    if (d.contains("previous")) t.previous = view("previous");
    if (d.contains("previous_field")) {
      previous_field = field_from_positions(view("previous_field"));
      t.previous_field = &previous_field;
    }
  }
  const ImageView style_view = py_bridge::view_of(style, "style");
  const ProgressCallback callback = py_bridge::python_progress(progress);
  SynthesisResult result;
  {
    py::gil_scoped_release release;
    result = stylize_frame(style_view, ex, tg, has_temporal ? &t : nullptr, opt, callback);
  }
  py::dict stats = py_bridge::frame_stats(result);
  return py::make_tuple(py_bridge::to_numpy(std::move(result.image)), stats);
}

void bind_job(py::module_& m) {
  py_bridge::ConfigClass<StylizeJobConfig> config(m, "StylizeJobConfig",
                                                  "StyLit's job (stylize_job.hpp); its options are StylitOptions.");
  py_bridge::light_path_shot_fields(py_bridge::job_config_fields(config));
  py::class_<StylizeJob, FrameJob>(m, "StylizeJob", "Stylization of a frame sequence; use tempera.methods.stylit.stylize.StylizeJob.")
      .def(py::init([](const StylizeJobConfig& config, const StylitOptions& options) {
             StylizeJobConfig c = job_config(config, options);
             py::gil_scoped_release release;  // reads the painting and checks every cache frame
             return std::make_unique<StylizeJob>(std::move(c));
           }),
           py::arg("config"), py::arg("options"))
      .def_property_readonly("report_path", &StylizeJob::report_path);
}

void bind_options(py::module_& m) {
  py_bridge::bind_options_class<StylitOptions>(m, "StylitOptions", stylit_option_table(),
                                               "Options of StyLit (native/include/tempera/methods/stylit/stylit.hpp).")
      .def_property(
          "weights", [](const StylitOptions& o) { return py_bridge::guide_weights_dict(o.weights); },
          [](StylitOptions& o, const py::object& w) { py_bridge::set_guide_weights(o.weights, w); },
                    "{guide: weight} in matching order (<= 0 leaves a guide out); setting names some guides, "
                    "the others keep their weights")
      .def_readwrite("synthesis", &StylitOptions::synthesis, "engine options (the quality preset sets the iterations)")
      .def(
          "validate", [](const StylitOptions& o) { checked(o); },
          "ValueError naming the first bad value (engine ranges, guide weights, temporal weight).");
}

void bind_stylit(py::module_& m) {
  bind_options(m);
  bind_job(m);
  m.def("stylize_frame", &stylize_frame_py, py::arg("style"), py::arg("exemplar"), py::arg("target"),
        py::arg("options"), py::arg("temporal") = py::none(), py::arg("progress") = py::none(),
        "One StyLit frame from in-memory guides; use tempera.methods.stylit.stylize.stylize_frame.");
  m.def(
      "flicker",
      [](const FloatArray& previous, const FloatArray& current, const FloatArray& velocity, const FloatArray& visible) {
        const ImageView p = py_bridge::view_of(previous, "previous"), c = py_bridge::view_of(current, "current"),
                        v = py_bridge::view_of(velocity, "velocity_backward"), m = py_bridge::view_of(visible, "visible");
        py::gil_scoped_release release;
        return flicker(p, c, v, m);
      },
      py::arg("previous"), py::arg("current"), py::arg("velocity_backward"), py::arg("visible"),
      "Mean absolute colour change along valid motion; use tempera.engine.temporal.flicker.");
}

// module.cpp runs it after the core's bindings (py_bridge::method_bindings).
const py_bridge::MethodBinding kBinding("stylit", bind_stylit);

}  // namespace

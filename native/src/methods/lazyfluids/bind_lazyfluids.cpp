// Python binding of LazyFluids (lazyfluids.hpp, lazyfluids_job.hpp);
// tempera.methods.lazyfluids.lazyfluids wraps it.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bind_frame_job.hpp"
#include "bind_frame_stats.hpp"
#include "bind_method.hpp"
#include "bind_job_config.hpp"
#include "bind_options.hpp"
#include "numpy_bridge.hpp"
#include "tempera/methods/lazyfluids/lazyfluids.hpp"
#include "tempera/methods/lazyfluids/lazyfluids_job.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

std::vector<ImageView> views(const py::list& arrays, const char* what, std::vector<FloatArray>& keep) {
  std::vector<ImageView> out;
  for (std::size_t i = 0; i < arrays.size(); ++i) {
    keep.push_back(arrays[i].cast<FloatArray>());
    out.push_back(py_bridge::view_of(keep.back(), concat(what, " ", i)));
  }
  return out;
}

// One frame (FluidFrameInput); None for what the first frame has not
// (advected, previous_field, flow_previous). Returns (image, stats).
py::tuple stylize_fluid_frame_py(const FloatArray& style, const FloatArray& previous_style,
                                 const FloatArray& target_alpha, const py::object& advected,
                                 const py::object& previous_field, const py::object& flow_previous,
                                 const LazyFluidsOptions& options, const py::object& progress) {
  std::vector<FloatArray> keep;
  auto view = [&](const py::object& array, const char* what) {
    if (array.is_none()) return ImageView();
    keep.push_back(array.cast<FloatArray>());
    return py_bridge::view_of(keep.back(), what);
  };
  FluidFrameInput in;
  in.style = view(style, "style");
  in.previous_style = view(previous_style, "previous style");
  in.target_alpha = view(target_alpha, "target alpha");
  in.advected = view(advected, "advected");
  in.flow_previous = view(flow_previous, "previous flow");
  OffsetField field;
  if (!previous_field.is_none()) {
    field = field_from_positions(view(previous_field, "previous field"));
    in.previous_field = &field;
  }
  const ProgressCallback callback = py_bridge::python_progress(progress);
  FluidFrameResult result;
  {
    py::gil_scoped_release release;
    result = stylize_fluid_frame(in, options, callback);
  }
  const py::dict stats = py_bridge::frame_stats(result.synthesis);
  return py::make_tuple(py_bridge::to_numpy(std::move(result.image)), stats);
}

void bind_lazyfluids(py::module_& m) {
  py_bridge::bind_options_class<LazyFluidsOptions>(m, "LazyFluidsOptions", lazyfluids_option_table(),
                                                   "Options of LazyFluids (native/include/tempera/methods/lazyfluids/lazyfluids.hpp).")
      .def_readwrite("synthesis", &LazyFluidsOptions::synthesis, "engine options (defaults: lazyfluids_defaults())");
  m.def("lazyfluids_defaults", &lazyfluids_defaults, "The engine options of LazyFluids.");
  m.def(
      "stylize_fluid_sequence",
      [](const py::list& exemplar, const py::list& alphas, const py::list& flows, const LazyFluidsOptions& options,
         const std::function<bool(double)>& progress) {
        std::vector<FloatArray> keep;
        const auto z = views(exemplar, "exemplar frame", keep), a = views(alphas, "target alpha", keep),
                   f = views(flows, "flow", keep);
        ProgressCallback callback = py_bridge::with_gil([&](double x) { return progress ? progress(x) : true; });
        std::vector<Image> out;
        {
          py::gil_scoped_release release;
          out = stylize_fluid_sequence(z, a, f, options, callback);
        }
        py::list result;
        for (auto& image : out) result.append(py_bridge::to_numpy(std::move(image)));
        return result;
      },
      py::arg("exemplar"), py::arg("alphas"), py::arg("flows"), py::arg("options"), py::arg("progress") = nullptr,
      "LazyFluids over arrays; use tempera.methods.lazyfluids.lazyfluids.stylize_sequence.");
  m.def("stylize_fluid_frame", &stylize_fluid_frame_py, py::arg("style"), py::arg("previous_style"),
        py::arg("target_alpha"), py::arg("advected"), py::arg("previous_field"), py::arg("flow_previous"),
        py::arg("options"), py::arg("progress") = py::none(),
        "One LazyFluids frame; use tempera.methods.lazyfluids.lazyfluids.stylize_frame.");
  m.def(
      "lazyfluids_advect_output",
      [](const FloatArray& previous_output, const FloatArray& flow_previous) {
        return py_bridge::to_numpy(advect_output(py_bridge::view_of(previous_output, "previous output"),
                                                 py_bridge::view_of(flow_previous, "previous flow")));
      },
      py::arg("previous_output"), py::arg("flow_previous"), "X^ of eq. 5.6: the previous output advected.");
  m.def(
      "lazyfluids_temporal_weights",
      [](const FloatArray& target_alpha, const FloatArray& advected, float lambda) {
        return py_bridge::to_numpy(temporal_weights(py_bridge::view_of(target_alpha, "target alpha"),
                                                    py_bridge::view_of(advected, "advected"), lambda));
      },
      py::arg("target_alpha"), py::arg("advected"), py::arg("lam"), "λ_q of eq. 5.6.");
  py::class_<LazyFluidsJob, FrameJob>(m, "LazyFluidsJob", "LazyFluids over a guide cache; use tempera.methods.lazyfluids.lazyfluids.FluidJob.")
      .def(py::init([](const JobConfig& config, const LazyFluidsOptions& options) {
             py_bridge::require_job_config(config, "FluidJob config");
             LazyFluidsJobConfig c;
             static_cast<JobConfig&>(c) = config;
             c.options = options;
             py::gil_scoped_release release;  // reads the exemplar and cache headers
             return std::make_unique<LazyFluidsJob>(std::move(c));
           }),
           py::arg("config"), py::arg("options"));
}

// module.cpp runs it after the core's bindings (py_bridge::method_bindings).
const py_bridge::MethodBinding kBinding("lazyfluids", bind_lazyfluids);

}  // namespace

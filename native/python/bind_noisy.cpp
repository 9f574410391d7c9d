// Python binding of Color Me Noisy (noisy.hpp); tempera.noisy wraps it.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bind_options.hpp"
#include "numpy_bridge.hpp"
#include "tempera/noisy.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

void bind_noisy(py::module_& m) {
  py_bridge::bind_options_class<NoisyOptions>(m, "NoisyOptions", noisy_option_table(),
                                              "Options of Color Me Noisy (native/include/tempera/noisy.hpp).")
      .def_readwrite("synthesis", &NoisyOptions::synthesis, "engine options (defaults: noisy_defaults())");
  m.def("noisy_defaults", &noisy_defaults, "The engine options Color Me Noisy uses.");
  m.def("noisy_levels", &noisy_levels, py::arg("noise"));
  m.def("noisy_box_widths", &noisy_box_widths, py::arg("noise"));
  m.def(
      "noisy_frame",
      [](const FloatArray& style, const FloatArray& reference, int frame, const NoisyOptions& options,
         std::optional<FloatArray> noise_map, const std::function<bool(double)>& progress) {
        const ImageView s = py_bridge::view_of(style, "exemplar"), r = py_bridge::view_of(reference, "reference frame");
        const ImageView map = noise_map ? py_bridge::view_of(*noise_map, "noise map") : ImageView{};
        ProgressCallback callback = py_bridge::with_gil([&](double f) { return progress ? progress(f) : true; });
        Image out;
        {
          py::gil_scoped_release release;
          out = noisy_frame(s, r, frame, options, map, callback);
        }
        return py_bridge::to_numpy(std::move(out));
      },
      py::arg("style"), py::arg("reference"), py::arg("frame"), py::arg("options"), py::arg("noise_map") = py::none(),
      py::arg("progress") = nullptr, "One Color Me Noisy frame; use tempera.noisy.noisy_frame.");
  m.def(
      "deform_exemplar",
      [](const FloatArray& style, const NoisyOptions& options, int frame) {
        const ImageView s = py_bridge::view_of(style, "exemplar");
        Image out;
        {
          py::gil_scoped_release release;
          out = deform_exemplar(s, options, frame);
        }
        return py_bridge::to_numpy(std::move(out));
      },
      py::arg("style"), py::arg("options"), py::arg("frame"), "The exemplar's MLS pre-deformation for a frame.");
}

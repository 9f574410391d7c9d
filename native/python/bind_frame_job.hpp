#pragma once
// The methods every per-frame job over a guide cache shows Python (the
// LazyFluids and Fluidymation jobs): its frames, warnings, output paths,
// one frame at a time with the GIL released, and the contact sheet.
#include <functional>
#include <string>
#include <utility>

#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "numpy_bridge.hpp"
#include "tempera/engine/synthesis.hpp"

namespace tempera::py_bridge {

// run_frame(index, progress) returns (status, seconds); progress(fraction)
// is called with the GIL held, and returning False cancels.
template <class Job, class Class>
Class& def_frame_job(Class& cls) {
  namespace py = pybind11;
  return cls.def_property_readonly("frames", &Job::frames)
      .def_property_readonly("warnings", &Job::warnings)
      .def("output_path", &Job::output_path)
      .def(
          "run_frame",
          [](Job& job, std::size_t index, const std::function<bool(double)>& progress) {
            ProgressCallback callback;
            if (progress) callback = with_gil([&](double f) { return progress(f); });
            decltype(job.run_frame(index, callback)) r;
            {
              py::gil_scoped_release release;
              r = job.run_frame(index, callback);
            }
            return py::make_tuple(r.status, r.seconds);
          },
          py::arg("index"), py::arg("progress") = nullptr)
      .def(
          "write_contact_sheet",
          [](const Job& job, const std::string& path, int columns) {
            py::gil_scoped_release release;
            job.write_contact_sheet(path, columns);
          },
          py::arg("path"), py::arg("columns") = 0);
}

}  // namespace tempera::py_bridge

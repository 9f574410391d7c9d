#pragma once
// What every per-frame job (app/frame_job.hpp) shows Python: its frames,
// warnings and output paths, and run_frame, one frame with the GIL
// released, returning the job core's one FrameResult as one dict; and, for
// the jobs that have one, the contact sheet.
#include <string>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "numpy_bridge.hpp"
#include "tempera/app/frame_result.hpp"
#include "tempera/engine/synthesis.hpp"

namespace tempera::py_bridge {

// Progress for code running without the GIL (with_gil); anything but an
// explicit False from the Python callable (or None) means "go on".
inline ProgressCallback python_progress(const pybind11::object& progress) {
  if (progress.is_none()) return {};
  return with_gil([progress](double fraction) { return !progress(fraction).is(pybind11::bool_(false)); });
}

// dict(frame, path, status, seconds, flicker (NaN where not measured), source_coverage).
inline pybind11::dict frame_result(const FrameResult& r) {
  pybind11::dict d;
  d["frame"] = r.frame;
  d["path"] = r.path;
  d["status"] = r.status;
  d["seconds"] = r.seconds;
  d["flicker"] = r.flicker;
  d["source_coverage"] = r.source_coverage;
  return d;
}

template <class Job, class Class>
Class& def_frame_job(Class& cls) {
  namespace py = pybind11;
  return cls.def_property_readonly("frames", &Job::frames)
      .def_property_readonly("warnings", &Job::warnings)
      .def("output_path", &Job::output_path, py::arg("frame"))
      .def(
          "run_frame",
          [](Job& job, std::size_t index, const py::object& progress) {
            const ProgressCallback callback = python_progress(progress);
            FrameResult r;
            {
              py::gil_scoped_release release;
              r = job.run_frame(index, callback);
            }
            return frame_result(r);
          },
          py::arg("index"), py::arg("progress") = py::none(),
          "Makes frames[index] or skips it when current; progress(fraction) returning False cancels.");
}

template <class Job, class Class>
Class& def_contact_sheet(Class& cls) {
  namespace py = pybind11;
  return cls.def(
      "write_contact_sheet",
      [](const Job& job, const std::string& path, int columns) {
        py::gil_scoped_release release;
        job.write_contact_sheet(path, columns);
      },
      py::arg("path"), py::arg("columns") = 0);
}

}  // namespace tempera::py_bridge

#pragma once
// What the bindings of jobs share: Python's progress callable for code
// running without the GIL, and the job core's one FrameResult as one dict.
// The per-frame job itself is bound once, as _native.FrameJob
// (bind_registry.cpp), the base of every per-frame job's class; so is the
// segment job, _native.SegmentJob.
#include <string>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "numpy_bridge.hpp"
#include "tempera/app/frame_result.hpp"
#include "tempera/app/segment_job.hpp"
#include "tempera/engine/synthesis.hpp"

namespace tempera::py_bridge {

// Progress for code running without the GIL (with_gil); anything but an
// explicit False from the Python callable (or None) means "go on".
inline ProgressCallback python_progress(const pybind11::object& progress) {
  if (progress.is_none()) return {};
  return with_gil([progress](double fraction) { return !progress(fraction).is(pybind11::bool_(false)); });
}

// The same for a segment job's stages: progress(fraction, finished stage or "").
inline StageProgress python_stage_progress(const pybind11::object& progress) {
  if (progress.is_none()) return {};
  return [progress](double fraction, const std::string& finished) {
    pybind11::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) throw pybind11::error_already_set();  // Ctrl-C
    return !progress(fraction, finished).is(pybind11::bool_(false));
  };
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

}  // namespace tempera::py_bridge

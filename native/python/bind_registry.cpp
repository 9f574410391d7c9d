// Python binding of the method registry (methods/registry.hpp) and of the
// job core: JobConfig, the registry's entries as dicts, FrameJob
// (app/frame_job.hpp) and SegmentJob (app/segment_job.hpp) as the base
// classes of every method's job (each method's job class derives from one
// in Python too), and method_job / method_segment_job, the job of any method
// with a job factory, so that a registered method runs from Python with no
// binding of its own (tempera.methods.registry.make_job).
#include <pybind11/stl.h>

#include "bind_frame_job.hpp"
#include "bind_job_config.hpp"
#include "tempera/app/frame_job.hpp"
#include "tempera/methods/registry.hpp"

namespace py = pybind11;
using namespace tempera;

namespace {

py::dict method_dict(const MethodEntry& e) {
  py::dict d;
  d["name"] = e.name, d["title"] = e.title, d["summary"] = e.summary, d["paper"] = e.paper;
  d["unit"] = e.unit, d["light_path_guides"] = e.light_path_guides, d["docs"] = e.docs;
  d["job"] = bool(e.make_job) || bool(e.make_segment_job);
  d["options_help"] = e.options_help;
  d["default_exemplar"] = e.default_exemplar;
  return d;
}

void bind_frame_job_class(py::module_& m) {
  py::class_<FrameJob>(m, "FrameJob", "The job core's per-frame job (app/frame_job.hpp); use tempera.app.frame_job.")
      .def_property_readonly("frames", &FrameJob::frames)
      .def_property_readonly("warnings", &FrameJob::warnings)
      .def_property_readonly("has_contact_sheet", &FrameJob::has_contact_sheet)
      .def_property_readonly("summary", &FrameJob::summary, "How the run went, in a phrase ('' if nothing to say).")
      .def("output_path", &FrameJob::output_path, py::arg("frame"))
      .def(
          "run_frame",
          [](FrameJob& job, std::size_t index, const py::object& progress) {
            const ProgressCallback callback = py_bridge::python_progress(progress);
            FrameResult r;
            {
              py::gil_scoped_release release;
              r = job.run_frame(index, callback);
            }
            return py_bridge::frame_result(r);
          },
          py::arg("index"), py::arg("progress") = py::none(),
          "Makes frames[index] or skips it when current; progress(fraction) returning False cancels.")
      .def(
          "write_contact_sheet",
          [](const FrameJob& job, const std::string& path, int columns) {
            if (!job.has_contact_sheet()) throw ValueError("this method writes no contact sheet");
            py::gil_scoped_release release;
            job.write_contact_sheet(path, columns);
          },
          py::arg("path"), py::arg("columns") = 0,
          "The exemplar followed by the frames written so far, as one image (atomic).");
}

void bind_segment_job_class(py::module_& m) {
  py::class_<SegmentJob>(m, "SegmentJob",
                         "The job core's segment job (app/segment_job.hpp); use tempera.app.segment_job.")
      .def_property_readonly("segments",
                             [](const SegmentJob& job) {
                               py::list out;
                               for (const auto& s : job.segments()) out.append(py::make_tuple(s.first, s.last, s.writes));
                               return out;
                             })
      .def_property_readonly("selected", &SegmentJob::selected)
      .def_property_readonly("whole_shot", &SegmentJob::whole_shot)
      .def_property_readonly("warnings", &SegmentJob::warnings)
      .def(
          "run_unit",
          [](SegmentJob& job, std::size_t index, const py::object& progress) {
            const StageProgress callback = py_bridge::python_stage_progress(progress);
            FrameResult r;
            {
              py::gil_scoped_release release;
              r = job.run_unit(index, callback);
            }
            return py_bridge::frame_result(r);
          },
          py::arg("index"), py::arg("progress") = py::none(),
          "Solves segments[index] or skips it when current; progress(fraction, finished stage or '') returning "
          "False cancels.")
      .def(
          "write_contact_sheet",
          [](const SegmentJob& job, const std::string& path, int columns) {
            py::gil_scoped_release release;
            job.write_contact_sheet(path, columns);
          },
          py::arg("path"), py::arg("columns") = 0,
          "The exemplar followed by the frames written so far, as one image (atomic).");
}

void bind_job_config_class(py::module_& m) {
  py_bridge::ConfigClass<JobConfig> c(m, "JobConfig", "What every job's config has (app/job_config.hpp).");
  py_bridge::job_config_fields(c);
}

// The job of `name` from the core's config (the frames go to OUT/frames) and
// the method's options as the command line takes them ((flag without "--",
// text) pairs; "" for a switch alone).
std::unique_ptr<FrameJob> method_job(const std::string& name, const JobConfig& config, const MethodOptions& options) {
  const MethodEntry& method = find_method(name);
  py::gil_scoped_release release;  // the job reads its inputs' headers
  return make_method_job(method, config, options);
}

// The same for a method whose unit is the segment.
std::unique_ptr<SegmentJob> method_segment_job(const std::string& name, const JobConfig& config,
                                               const MethodOptions& options) {
  const MethodEntry& method = find_method(name);
  py::gil_scoped_release release;  // the job reads its inputs' headers
  return make_method_segment_job(method, config, options);
}

}  // namespace

void bind_registry(py::module_& m) {
  bind_job_config_class(m);
  bind_frame_job_class(m);
  bind_segment_job_class(m);
  m.attr("JOB_MADE_EXEMPLAR") = kJobMadeExemplar;
  m.attr("KIT_EXEMPLAR") = kKitExemplar;
  m.def(
      "methods",
      [] {
        py::list out;
        for (const MethodEntry& e : method_registry()) out.append(method_dict(e));
        return out;
      },
      "The method registry (methods/registry.hpp): a dict per method (name, title, summary, paper, unit, "
      "light_path_guides, docs, job: has a job factory (a segment job's for the unit 'segment'), "
      "options_help, default_exemplar), in the panel's order.");
  m.def(
      "default_method", [] { return default_method().name; },
      "The name of the method when none is named (tempera stylize without --method): the registry's first.");
  m.def(
      "find_method", [](const std::string& name) { return method_dict(find_method(name)); }, py::arg("name"),
      "The registry's entry of `name`; ValueError naming every method.");
  m.def("method_segment_job", &method_segment_job, py::arg("name"), py::arg("config"),
        py::arg("options") = MethodOptions{},
        "The SegmentJob of a method whose unit is the segment, as tempera stylize --method NAME runs it.");
  m.def("method_job", &method_job, py::arg("name"), py::arg("config"), py::arg("options") = MethodOptions{},
        "The FrameJob of a method with a job factory, as tempera stylize --method NAME runs it; ValueError for "
        "an unknown method, option or value, or a method without one.");
}

// Python binding of Fluidymation (fluidymation.hpp, fluidymation_job.hpp);
// tempera.methods.fluidymation.fluidymation wraps it.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bind_method.hpp"
#include "bind_job_config.hpp"
#include "bind_options.hpp"
#include "numpy_bridge.hpp"
#include "tempera/methods/fluidymation/fluidymation.hpp"
#include "tempera/methods/fluidymation/fluidymation_job.hpp"
#include "tempera/methods/fluidymation/mask_flow.hpp"
#include "tempera/methods/fluidymation/motion_extent.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

// Views of a list of arrays, kept alive in `keep`.
std::vector<ImageView> views(const py::list& arrays, const std::string& what, std::vector<FloatArray>& keep) {
  std::vector<ImageView> out;
  keep.reserve(keep.size() + arrays.size());
  for (std::size_t i = 0; i < arrays.size(); ++i) {
    keep.push_back(arrays[i].cast<FloatArray>());
    out.push_back(py_bridge::view_of(keep.back(), concat(what, " ", i)));
  }
  return out;
}

py::list to_list(std::vector<Image>&& images) {
  py::list out;
  for (Image& i : images) out.append(py_bridge::to_numpy(std::move(i)));
  return out;
}

void bind_fluidymation(py::module_& m) {
  py_bridge::bind_options_class<FluidymationOptions>(m, "FluidymationOptions", fluidymation_option_table(),
                                                     "Options of Fluidymation (native/include/tempera/methods/fluidymation/fluidymation.hpp).")
      .def_readwrite("synthesis", &FluidymationOptions::synthesis, "engine options (defaults: fluidymation_defaults())")
      .def(
          "validate", [](const FluidymationOptions& o) { validate(o); },
          "ValueError naming the first bad value (ranges, and m_u > m_l).");
  m.def("fluidymation_defaults", &fluidymation_defaults, "The engine options of Fluidymation.");
  m.def(
      "flow_from_masks",
      [](const py::list& masks, float temporal_radius) {
        std::vector<FloatArray> keep;
        const std::vector<ImageView> v = views(masks, "mask", keep);
        std::vector<Image> out;
        {
          py::gil_scoped_release release;
          out = flow_from_masks(v, temporal_radius);
        }
        return to_list(std::move(out));
      },
      py::arg("masks"), py::arg("temporal_radius") = 3.0f, "Flows of a mask sequence (App. A); see mask_flow.hpp.");
  m.def(
      "motion_extent",
      [](const py::list& flows, const py::list& masks) {
        std::vector<FloatArray> keep;
        const std::vector<ImageView> f = views(flows, "flow", keep), k = views(masks, "mask", keep);
        MotionExtent e;
        {
          py::gil_scoped_release release;
          e = motion_extent(f, k);
        }
        return py::make_tuple(to_list(std::move(e.forward)), to_list(std::move(e.backward)));
      },
      py::arg("flows"), py::arg("masks"), "ext+ and ext- per frame; see motion_extent.hpp.");
  m.def(
      "stylize_fluid_sequence",
      [](const py::list& exemplar, const py::list& exemplar_masks, const py::list& target_masks,
         const py::object& target_flows, const FluidymationOptions& options, const std::function<bool(double)>& progress) {
        std::vector<FloatArray> keep;
        FluidSequence seq;
        seq.exemplar = views(exemplar, "exemplar frame", keep);
        seq.exemplar_masks = views(exemplar_masks, "exemplar mask", keep);
        seq.target_masks = views(target_masks, "target mask", keep);
        if (!target_flows.is_none()) seq.target_flows = views(target_flows.cast<py::list>(), "target flow", keep);
        ProgressCallback callback = py_bridge::with_gil([&](double f) { return progress ? progress(f) : true; });
        std::vector<FluidFrame> out;
        {
          py::gil_scoped_release release;
          out = stylize_fluid_sequence(seq, options, callback);
        }
        py::list result;
        for (FluidFrame& f : out) {
          py::dict d;
          d["image"] = py_bridge::to_numpy(std::move(f.image));
          d["nnf"] = py_bridge::to_numpy(std::move(f.nnf));
          d["time_shift"] = py_bridge::to_numpy(std::move(f.time_shift));
          d["energy"] = f.energy;
          result.append(d);
        }
        return result;
      },
      py::arg("exemplar"), py::arg("exemplar_masks"), py::arg("target_masks"), py::arg("target_flows"),
      py::arg("options"), py::arg("progress") = nullptr, "Use tempera.methods.fluidymation.fluidymation.stylize_sequence.");
  py_bridge::ConfigClass<FluidymationJobConfig> config(
      m, "FluidymationJobConfig", "Fluidymation over a guide cache (fluidymation_job.hpp); its options are FluidymationOptions.");
  py_bridge::job_config_fields(config)
      .field("exemplar_masks", &FluidymationJobConfig::exemplar_masks,
             "folder of the exemplar's mask frames (first channel); '' the exemplar's alpha")
      .field("target_mask", &FluidymationJobConfig::target_mask, "alpha | mask.OB_<name> | mask.CO_<name>")
      .field("flow", &FluidymationJobConfig::flow,
             "auto: the cache's fluid_velocity, else velocity_forward, else the masks");
  py::class_<FluidymationJob, FrameJob>(m, "FluidymationJob", "Fluidymation over a guide cache; use tempera.methods.fluidymation.fluidymation.MediaJob.")
      .def(py::init([](const FluidymationJobConfig& config, const FluidymationOptions& options) {
             py_bridge::require_job_config(config, "MediaJob config");
             FluidymationJobConfig c = config;
             c.options = options;
             py::gil_scoped_release release;  // reads the exemplar and the target's masks
             return std::make_unique<FluidymationJob>(std::move(c));
           }),
           py::arg("config"), py::arg("options"))
      .def_property_readonly("flow_guide", &FluidymationJob::flow_guide);
}

// module.cpp runs it after the core's bindings (py_bridge::method_bindings).
const py_bridge::MethodBinding kBinding("fluidymation", bind_fluidymation);

}  // namespace

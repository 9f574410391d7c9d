// Python binding of Color Me Noisy (noisy.hpp); tempera.methods.noisy.noisy wraps it.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <tuple>

#include "bind_method.hpp"
#include "bind_job_config.hpp"
#include "bind_options.hpp"
#include "numpy_bridge.hpp"
#include "tempera/methods/noisy/noisy_sequence.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

void bind_sequence(py::module_& m) {
  py_bridge::ConfigClass<NoisySequenceConfig> config(
      m, "NoisySequenceConfig", "Color Me Noisy over a folder of frames (noisy_sequence.hpp); its options are NoisyOptions.");
  py_bridge::job_config_fields(config)
      .field("reference", &NoisySequenceConfig::reference, "folder of the coherent frames R: PREFIX0001.png ...")
      .field("prefix", &NoisySequenceConfig::prefix, "of the reference and the output frames")
      .field("noise_map", &NoisySequenceConfig::noise_map,
             "local noise map (an image file, or a guide of `guides`); '' the same noise everywhere")
      .field("exemplar_guides", &NoisySequenceConfig::exemplar_guides, "guided noise: the exemplar render's guide cache")
      .field("exemplar_frame", &NoisySequenceConfig::exemplar_frame, "frame of exemplar_guides (None: its only frame)")
      .field("guide_weights", &NoisySequenceConfig::guide_weights, "guided noise: [(light-path guide, weight)]");
  py::class_<NoisySequence, FrameJob>(m, "NoisySequence", "Color Me Noisy over a folder of frames; use tempera.methods.noisy.noisy.NoisySequence.")
      .def(py::init([](const NoisySequenceConfig& config, const NoisyOptions& options) {
             py_bridge::require_job_config(config, "NoisySequence config");
             if (config.reference.empty()) throw ValueError("NoisySequence config needs 'reference'");
             NoisySequenceConfig c = config;
             c.options = options;
             py::gil_scoped_release release;  // reads the medium, checks every frame
             return std::make_unique<NoisySequence>(std::move(c));
           }),
           py::arg("config"), py::arg("options"));
}

void bind_noisy(py::module_& m) {
  bind_sequence(m);
  py_bridge::bind_options_class<NoisyOptions>(m, "NoisyOptions", noisy_option_table(),
                                              "Options of Color Me Noisy (native/include/tempera/methods/noisy/noisy.hpp).")
      .def_readwrite("synthesis", &NoisyOptions::synthesis, "engine options (defaults: noisy_defaults())");
  m.def("noisy_defaults", &noisy_defaults, "The engine options Color Me Noisy uses.");
  m.def("noisy_levels", &noisy_levels, py::arg("noise"));
  m.def("noisy_box_widths", &noisy_box_widths, py::arg("noise"));
  m.def(
      "noisy_frame",
      [](const FloatArray& style, const FloatArray& reference, int frame, const NoisyOptions& options,
         std::optional<FloatArray> noise_map, const std::function<bool(double)>& progress,
         const std::vector<std::tuple<std::string, FloatArray, FloatArray, float>>& guide_pairs) {
        const ImageView s = py_bridge::view_of(style, "exemplar"), r = py_bridge::view_of(reference, "reference frame");
        const ImageView map = noise_map ? py_bridge::view_of(*noise_map, "noise map") : ImageView{};
        std::vector<NoisyGuide> guides;  // (name, exemplar side, frame side, weight)
        for (const auto& [name, source, target, weight] : guide_pairs)
          guides.push_back({name, py_bridge::view_of(source, "exemplar guide " + name),
                            py_bridge::view_of(target, "frame guide " + name), weight});
        ProgressCallback callback = py_bridge::with_gil([&](double f) { return progress ? progress(f) : true; });
        Image out;
        {
          py::gil_scoped_release release;
          out = noisy_frame(s, r, frame, options, map, callback, guides);
        }
        return py_bridge::to_numpy(std::move(out));
      },
      py::arg("style"), py::arg("reference"), py::arg("frame"), py::arg("options"), py::arg("noise_map") = py::none(),
      py::arg("progress") = nullptr, py::arg("guides") = std::vector<std::tuple<std::string, FloatArray, FloatArray, float>>{},
      "One Color Me Noisy frame; use tempera.methods.noisy.noisy.noisy_frame.");
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

// module.cpp runs it after the core's bindings (py_bridge::method_bindings).
const py_bridge::MethodBinding kBinding("noisy", bind_noisy);

}  // namespace

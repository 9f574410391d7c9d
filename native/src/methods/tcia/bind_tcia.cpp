// Python binding of Bénard et al. 2013 (tcia.hpp); tempera.methods.tcia.tcia wraps it.
#include <deque>
#include <numeric>

#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bind_method.hpp"
#include "bind_job_config.hpp"
#include "bind_options.hpp"
#include "numpy_bridge.hpp"
#include "tempera/methods/tcia/tcia.hpp"
#include "tempera/methods/tcia/tcia_job.hpp"
#include "tempera/methods/tcia/tcia_layers.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

ImageView keep_view(const py::handle& array, const std::string& what, std::vector<FloatArray>& keep) {
  keep.push_back(py::reinterpret_borrow<py::object>(array).cast<FloatArray>());
  return py_bridge::view_of(keep.back(), what);
}

// The job's configuration from tempera.methods.tcia.tcia.ShotJob's keywords (checked there).
TciaJobConfig job_config(const py::dict& d, const TciaOptions& options) {
  TciaJobConfig c;
  py_bridge::read_job_config(d, c, "ShotJob config");
  c.exemplar_guides = d["exemplar_guides"].cast<std::string>();
  if (!d["exemplar_frame"].is_none()) c.exemplar_frame = d["exemplar_frame"].cast<int>();
  std::string weights;
  for (const auto& [name, weight] : d["weights"].cast<py::dict>())
    weights += concat(weights.empty() ? "" : ",", std::string(py::str(name)), "=", py::str(weight).cast<std::string>());
  parse_guide_weights(weights, c.weights);
  active_guides(c.weights);
  for (const auto& key : d["keys"].cast<py::list>()) {
    const auto t = key.cast<py::tuple>();
    c.keys.push_back({t[0].cast<int>(), t[1].cast<std::string>(), t[2].is_none() ? "" : t[2].cast<std::string>()});
  }
  for (const auto& layer : d["layers"].cast<py::list>()) {
    const auto t = layer.cast<py::tuple>();
    c.layers.push_back({t[0].cast<std::string>(), t[1].cast<std::string>(), t[2].is_none() ? "" : t[2].cast<std::string>(), {}});
    if (t.size() > 3)  // the layer's own keys
      for (const auto& key : t[3].cast<py::list>()) {
        const auto k = key.cast<py::tuple>();
        c.layers.back().keys.push_back(
            {k[0].cast<int>(), k[1].cast<std::string>(), k[2].is_none() ? "" : k[2].cast<std::string>()});
      }
  }
  c.layer_order = d["layer_order"].cast<std::string>();
  if (!d["segment"].is_none()) c.segment = d["segment"].cast<std::pair<int, int>>();
  c.tcia = options;
  py_bridge::set_from_dict(c.lines, tcia_line_option_table(), d["lines"].cast<py::dict>(), "line option");
  py_bridge::set_from_dict(c.orientation, tcia_orientation_option_table(), d["orientation"].cast<py::dict>(),
                           "orientation option");
  return c;
}

// The Shot of tempera.methods.tcia.tcia.stylize_shot's arguments; its views point into `keep`.
Shot shot_from(const FloatArray& style, const py::list& guides, const py::list& frames, const py::list& keys,
               const py::object& style_orientation, std::vector<FloatArray>& keep) {
  Shot shot;
  shot.style = py_bridge::view_of(style, "style");
  for (const auto& g : guides) {
    const auto t = g.cast<py::tuple>();
    shot.guide_names.push_back(t[0].cast<std::string>());
    shot.style_guides.push_back(keep_view(t[1], "exemplar guide '" + shot.guide_names.back() + "'", keep));
    shot.guide_weights.push_back(t[2].cast<float>());
  }
  if (!style_orientation.is_none()) shot.style_orientation = keep_view(style_orientation, "style orientation", keep);
  std::size_t k = 0;
  for (const auto& item : frames) {
    const py::dict d = item.cast<py::dict>();
    const std::string what = concat("frame ", k++);
    ShotFrame f;
    for (const char* key : {"guides", "velocity_backward", "velocity_forward", "occlusion_backward", "occlusion_forward"})
      if (!d.contains(key)) throw ValueError(concat(what, " needs '", key, "'"));
    for (const auto& g : d["guides"].cast<py::list>()) f.guides.push_back(keep_view(g, what + " guide", keep));
    f.velocity_backward = keep_view(d["velocity_backward"], what + " velocity_backward", keep);
    f.velocity_forward = keep_view(d["velocity_forward"], what + " velocity_forward", keep);
    f.occlusion_backward = keep_view(d["occlusion_backward"], what + " occlusion_backward", keep);
    f.occlusion_forward = keep_view(d["occlusion_forward"], what + " occlusion_forward", keep);
    if (d.contains("orientation")) f.orientation = keep_view(d["orientation"], what + " orientation", keep);
    shot.frames.push_back(std::move(f));
  }
  for (const auto& item : keys) {
    const auto t = item.cast<py::tuple>();
    ShotKey key;
    key.frame = t[0].cast<int>();
    key.painting = keep_view(t[1], concat("the painting of key ", key.frame), keep);
    if (!t[2].is_none()) key.mask = keep_view(t[2], concat("the mask of key ", key.frame), keep);
    shot.keys.push_back(key);
  }
  return shot;
}

void bind_tcia(py::module_& m) {
  py::class_<TciaJob, SegmentJob>(m, "TciaJob",
                                  "The coherent method over a guide cache; use tempera.methods.tcia.tcia.ShotJob.")
      .def(py::init([](const py::dict& config, const TciaOptions& options) {
             TciaJobConfig c = job_config(config, options);
             py::gil_scoped_release release;  // reads the painting, keys and cache headers
             return std::make_unique<TciaJob>(std::move(c));
           }),
           py::arg("config"), py::arg("options"))
      .def("output_path", &TciaJob::output_path, py::arg("frame"))
      .def("record_path", &TciaJob::record_path)
      .def("layer_path", &TciaJob::layer_path, py::arg("layer"), py::arg("frame"))
      .def(
          "run_segment",
          [](TciaJob& job, std::size_t index, const std::function<bool(py::dict)>& progress) {
            SegmentProgress callback;
            if (progress)
              callback = [&](const SweepProgress& p) {
                py::gil_scoped_acquire acquire;
                if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C
                py::dict d;
                d["level"] = p.level, d["levels"] = p.levels, d["direction"] = p.direction, d["frame"] = p.frame;
                d["fraction"] = p.fraction;
                return progress(d);
              };
            SegmentResult r;
            {
              py::gil_scoped_release release;
              r = job.run_segment(index, callback);
            }
            return py::make_tuple(r.status, r.seconds);
          },
          py::arg("index"), py::arg("progress") = nullptr);
  py_bridge::bind_options_class<TciaOptions>(m, "TciaOptions", tcia_option_table(),
                                             "Options of Bénard et al. 2013 (native/include/tempera/methods/tcia/tcia.hpp).")
      .def_readwrite("synthesis", &TciaOptions::synthesis, "engine options (defaults: tcia_defaults())");
  m.def("tcia_defaults", &tcia_defaults, "The engine options of the coherent method.");
  m.def(
      "tcia_key_frames",
      [](const std::vector<std::string>& keys, const std::vector<std::string>& layer_keys) {
        std::vector<int> frames;
        for (const auto& text : keys) frames.push_back(parse_key(text).frame);
        for (const auto& text : layer_keys) frames.push_back(parse_layer_key(text).second.frame);
        return frames;
      },
      py::arg("keys"), py::arg("layer_keys"),
      "The frames of the CLI's --key F=PATH[,MASK] and --layer-key NAME:F=PATH[,MASK] texts, read as the CLI "
      "reads them (ValueError naming a bad one): with key_segments, the farm's segments are the job's.");
  m.def(
      "stylize_shot",
      [](const FloatArray& style, const py::list& guides, const py::list& frames, const py::list& keys,
         const TciaOptions& options, const std::function<bool(double)>& progress, const py::object& style_orientation) {
        std::vector<FloatArray> keep;
        const Shot shot = shot_from(style, guides, frames, keys, style_orientation, keep);
        ProgressCallback callback = py_bridge::with_gil([&](double f) { return progress ? progress(f) : true; });
        std::vector<Image> out;
        {
          py::gil_scoped_release release;
          out = stylize_shot(shot, options, callback);
        }
        py::list result;
        for (auto& image : out) result.append(py_bridge::to_numpy(std::move(image)));
        return result;
      },
      py::arg("style"), py::arg("guides"), py::arg("frames"), py::arg("keys"), py::arg("options"),
      py::arg("progress") = nullptr, py::arg("style_orientation") = py::none(),
      "A whole shot with Bénard et al. 2013's sweeps; use tempera.methods.tcia.tcia.stylize_shot.");
  m.def(
      "stylize_shot_layers",
      [](const FloatArray& style, const py::list& guides, const py::list& frames, const py::list& keys,
         const py::list& layers, bool extrapolate, const TciaOptions& options,
         const std::function<bool(double)>& progress) {
        std::vector<FloatArray> keep;
        const Shot shot = shot_from(style, guides, frames, keys, py::none(), keep);
        std::vector<ShotLayer> spec;
        for (const auto& item : layers) {
          const auto t = item.cast<py::tuple>();
          ShotLayer& l = spec.emplace_back();
          l.name = t[0].cast<std::string>();
          for (const auto& m : t[1].cast<py::list>()) l.masks.push_back(keep_view(m, "the mask of layer " + l.name, keep));
          if (!t[2].is_none()) l.style = keep_view(t[2], "the painting of layer " + l.name, keep);
          if (!t[3].is_none()) l.style_mask = keep_view(t[3], "the exemplar mask of layer " + l.name, keep);
        }
        std::vector<std::vector<Image>> out;
        {
          py::gil_scoped_release release;
          for (std::size_t i = 0; i < spec.size(); ++i) {
            ProgressCallback callback = py_bridge::with_gil(
                [&](double f) { return progress ? progress((double(i) + f) / double(spec.size())) : true; });
            std::deque<Image> hold;
            out.push_back(stylize_shot(layer_shot(shot, spec[i], hold, extrapolate), options, callback));
          }
        }
        py::list result;
        for (auto& frames_of_layer : out) {
          py::list l;
          for (auto& image : frames_of_layer) l.append(py_bridge::to_numpy(std::move(image)));
          result.append(l);
        }
        return result;
      },
      py::arg("style"), py::arg("guides"), py::arg("frames"), py::arg("keys"), py::arg("layers"),
      py::arg("extrapolate"), py::arg("options"), py::arg("progress") = nullptr,
      "Each layer of a shot solved alone (tcia_layers.hpp); use tempera.methods.tcia.tcia.stylize_layers.");
  m.def(
      "composite_layers",
      [](const py::list& images, const py::list& masks, const py::object& depth) {
        std::vector<FloatArray> keep;
        std::vector<ImageView> i, a;
        for (const auto& x : images) i.push_back(keep_view(x, "layer image", keep));
        for (const auto& x : masks) a.push_back(keep_view(x, "layer mask", keep));
        std::vector<int> order(i.size());
        std::iota(order.begin(), order.end(), 0);
        if (!depth.is_none()) order = depth_order(keep_view(depth, "depth", keep), a);
        return py_bridge::to_numpy(composite_layers(i, a, order));
      },
      py::arg("images"), py::arg("masks"), py::arg("depth") = py::none(),
      "The layers composited back to front (tcia_layers.hpp); use tempera.methods.tcia.tcia.composite.");
}

// module.cpp runs it after the core's bindings (py_bridge::method_bindings).
const py_bridge::MethodBinding kBinding("tcia", bind_tcia);

}  // namespace

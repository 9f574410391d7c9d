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

// The job's config and its parts, field by field.
void bind_config(py::module_& m) {
  py_bridge::bind_options_class<TciaLineOptions>(m, "TciaLineOptions", tcia_line_option_table(),
                                                 "The line term of eq. 9 (tcia_job.hpp).");
  py_bridge::bind_options_class<TciaOrientationOptions>(m, "TciaOrientationOptions", tcia_orientation_option_table(),
                                                        "Patches turned by the guide cache's orientation (tcia_job.hpp).");
  py_bridge::ConfigClass<KeyFile> key(m, "TciaKey", "A painted keyframe (tcia_job.hpp KeyFile; the CLI's --key).");
  key.field("frame", &KeyFile::frame, "the frame it paints")
      .field("painting", &KeyFile::painting, "the painting's file")
      .field("mask", &KeyFile::mask, "where the painting counts (an image file); '' everywhere");
  py_bridge::ConfigClass<LayerFile> layer(m, "TciaLayer", "A layer solved on its own (tcia_job.hpp LayerFile; --layer).");
  layer.field("name", &LayerFile::name, "its folder's name: OUT/layers/NAME/")
      .field("mask", &LayerFile::mask, "its mask guide: mask.OB_<object> or mask.CO_<collection>")
      .field("painting", &LayerFile::painting, "its own painting; '' the shot's")
      .field("keys", &LayerFile::keys, "its own keys (TciaKey), in place of the shot's at their frames");
  py_bridge::ConfigClass<TciaJobConfig> config(
      m, "TciaJobConfig", "The coherent method over a guide cache (tcia_job.hpp); its options are TciaOptions.");
  py_bridge::light_path_shot_fields(py_bridge::job_config_fields(config))
      .field_with(
          "weights", py::cpp_function([](const TciaJobConfig& c) { return py_bridge::guide_weights_dict(c.weights); }),
          [](TciaJobConfig& c, const py::handle& w) { py_bridge::set_guide_weights(c.weights, w); },
          "{guide: weight} in matching order; setting names some guides, the others keep theirs")
      .field("keys", &TciaJobConfig::keys, "the painted keyframes (TciaKey)")
      .field("segment", &TciaJobConfig::segment, "(first, last): only that segment (a farm task); None: the shot")
      .field("lines", &TciaJobConfig::lines, "the line term (TciaLineOptions)")
      .field("layers", &TciaJobConfig::layers, "layers solved separately and composited (TciaLayer)")
      .field("layer_order", &TciaJobConfig::layer_order, "depth (per frame, the cache's depth) | given (first at the back)")
      .field("orientation", &TciaJobConfig::orientation, "patches turned by the cache's orientation (TciaOrientationOptions)");
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
  bind_config(m);
  py::class_<TciaJob, SegmentJob>(m, "TciaJob",
                                  "The coherent method over a guide cache; use tempera.methods.tcia.tcia.ShotJob.")
      .def(py::init([](const TciaJobConfig& config, const TciaOptions& options) {
             py_bridge::require_light_path_shot(config, "ShotJob config");
             TciaJobConfig c = config;
             active_guides(c.weights);
             c.tcia = options;
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

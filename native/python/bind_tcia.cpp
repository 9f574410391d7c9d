// Python binding of Bénard et al. 2013 (tcia.hpp); tempera.tcia wraps it.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bind_options.hpp"
#include "numpy_bridge.hpp"
#include "tempera/tcia.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

ImageView keep_view(const py::handle& array, const std::string& what, std::vector<FloatArray>& keep) {
  keep.push_back(py::reinterpret_borrow<py::object>(array).cast<FloatArray>());
  return py_bridge::view_of(keep.back(), what);
}

}  // namespace

void bind_tcia(py::module_& m) {
  py_bridge::bind_options_class<TciaOptions>(m, "TciaOptions", tcia_option_table(),
                                             "Options of Bénard et al. 2013 (native/include/tempera/tcia.hpp).")
      .def_readwrite("synthesis", &TciaOptions::synthesis, "engine options (defaults: tcia_defaults())");
  m.def("tcia_defaults", &tcia_defaults, "The engine options of the coherent method.");
  m.def(
      "stylize_shot",
      [](const FloatArray& style, const py::list& guides, const py::list& frames, const py::list& keys,
         const TciaOptions& options, const std::function<bool(double)>& progress) {
        std::vector<FloatArray> keep;
        Shot shot;
        shot.style = py_bridge::view_of(style, "style");
        for (const auto& g : guides) {
          const auto t = g.cast<py::tuple>();
          shot.guide_names.push_back(t[0].cast<std::string>());
          shot.style_guides.push_back(keep_view(t[1], "exemplar guide '" + shot.guide_names.back() + "'", keep));
          shot.guide_weights.push_back(t[2].cast<float>());
        }
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
      py::arg("progress") = nullptr,
      "A whole shot with Bénard et al. 2013's sweeps; use tempera.tcia.stylize_shot.");
}

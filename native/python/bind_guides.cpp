// Python binding of the guide building blocks (motion, orientation, line
// distance). Arrays are viewed in place and the GIL is released while the
// native code runs; tempera.engine.guides wraps these with numpy-friendly shapes.
#include <pybind11/stl.h>

#include "numpy_bridge.hpp"
#include "tempera/app/guide_cache.hpp"
#include "tempera/app/light_path_guides.hpp"
#include "tempera/engine/distance_transform.hpp"
#include "tempera/engine/motion.hpp"
#include "tempera/engine/orientation.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

// Runs fn(views...) without the GIL and hands the resulting Image to numpy.
template <typename Fn>
py::array_t<float> without_gil(Fn&& fn) {
  Image out;
  {
    py::gil_scoped_release release;
    out = fn();
  }
  return py_bridge::to_numpy(std::move(out));
}

}  // namespace

void bind_guides(py::module_& m) {
  m.def(
      "light_path_guides",
      [] {
        py::list out;
        for (const auto& g : light_path_guides()) {
          py::dict d;
          d["name"] = g.name;
          d["expression"] = g.expression;
          d["weight"] = g.weight;
          d["label"] = g.label;
          d["help"] = g.help;
          out.append(d);
        }
        return out;
      },
      "The light-path guides: name, expression, default weight, label, help (the one table, app/light_path_guides.hpp).");
  m.def(
      "tonemap_guide",
      [](const FloatArray& linear) {
        const ImageView v = py_bridge::view_of(linear, "linear");
        Image out;
        {
          py::gil_scoped_release release;
          out = tonemap_guide(v);
        }
        return py_bridge::to_numpy(std::move(out));
      },
      py::arg("linear"), "Linear radiance -> guide values in [0, 1): x/(1+x), then sRGB (use tempera.engine.guides.tonemap).");
  m.def(
      "cache_guides",
      [] {
        py::list out;
        for (const CacheGuide& g : cache_guides()) {
          py::dict d;
          d["name"] = g.name;
          d["components"] = g.components;
          d["meaning"] = g.meaning;
          out.append(d);
        }
        return out;
      },
      "The guide cache's guides besides the light paths: name, channel components, meaning (app/guide_cache.hpp).");
  m.def(
      "occlusion_backward",
      [](const FloatArray& v_minus_t, const FloatArray& v_plus_prev, float epsilon) {
        ImageView a = py_bridge::view_of(v_minus_t, "v_minus_t"), b = py_bridge::view_of(v_plus_prev, "v_plus_prev");
        return without_gil([&] { return occlusion_backward(a, b, epsilon); });
      },
      py::arg("v_minus_t"), py::arg("v_plus_prev"), py::arg("epsilon") = 2.0f,
      "chi-(p, t): 1 where p was visible in frame t-1 (Benard 2013, 3.1); use tempera.engine.guides.");
  m.def(
      "occlusion_forward",
      [](const FloatArray& v_plus_t, const FloatArray& v_minus_next, float epsilon) {
        ImageView a = py_bridge::view_of(v_plus_t, "v_plus_t"), b = py_bridge::view_of(v_minus_next, "v_minus_next");
        return without_gil([&] { return occlusion_forward(a, b, epsilon); });
      },
      py::arg("v_plus_t"), py::arg("v_minus_next"), py::arg("epsilon") = 2.0f,
      "chi+(p, t): 1 where p stays visible in frame t+1 (Benard 2013, 3.1); use tempera.engine.guides.");
  m.def(
      "warp_backward",
      [](const FloatArray& previous, const FloatArray& v_minus_t) {
        ImageView a = py_bridge::view_of(previous, "previous"), b = py_bridge::view_of(v_minus_t, "v_minus_t");
        return without_gil([&] { return warp_backward(a, b); });
      },
      py::arg("previous"), py::arg("v_minus_t"), "previous(p - V-_t(p)), bilinear; use tempera.engine.guides.");
  m.def(
      "structure_tensor",
      [](const FloatArray& image, float sigma) {
        ImageView a = py_bridge::view_of(image, "image");
        return without_gil([&] { return structure_tensor(a, sigma); });
      },
      py::arg("image"), py::arg("sigma") = 2.0f, "(Jxx, Jxy, Jyy) per pixel; use tempera.engine.guides.");
  m.def(
      "orientation_from_tensor",
      [](const FloatArray& tensor) {
        ImageView a = py_bridge::view_of(tensor, "structure tensor");
        return without_gil([&] { return orientation_from_tensor(a); });
      },
      py::arg("tensor"), "(angle in [0, pi), coherence) per pixel; use tempera.engine.guides.");
  m.def(
      "line_distance",
      [](const FloatArray& mask, float d_max) {
        ImageView a = py_bridge::view_of(mask, "line mask");
        return without_gil([&] { return line_distance(a, d_max); });
      },
      py::arg("mask"), py::arg("d_max") = 10.0f, "min(distance to lines, d_max) / d_max; use tempera.engine.guides.");
}

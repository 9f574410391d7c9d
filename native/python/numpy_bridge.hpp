#pragma once
// numpy <-> tempera images without needless copies: inputs are viewed in place
// when they are float32 and C-contiguous; outputs hand their buffer to numpy.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <functional>
#include <memory>
#include <string>

#include "tempera/engine/error.hpp"
#include "tempera/engine/image.hpp"

namespace tempera::py_bridge {

namespace py = pybind11;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

// (H, W) or (H, W, C) float32 array -> view. The array must outlive the view.
inline ImageView view_of(const FloatArray& array, const std::string& what) {
  if (array.ndim() != 2 && array.ndim() != 3)
    throw ValueError(concat(what, " must be an (H, W) or (H, W, C) array, got ", array.ndim(),
                            " dimensions"));
  ImageView view;
  view.data = array.data();
  view.height = int(array.shape(0));
  view.width = int(array.shape(1));
  view.channels = array.ndim() == 3 ? int(array.shape(2)) : 1;
  require_nonempty(view, what);
  return view;
}

// Moves an Image into a numpy array of shape (H, W, C) that owns it.
inline py::array_t<float> to_numpy(Image&& image) {
  auto* owned = new Image(std::move(image));
  py::capsule free_when_done(owned, [](void* p) { delete static_cast<Image*>(p); });
  const py::ssize_t h = owned->height(), w = owned->width(), c = owned->channels();
  return py::array_t<float>({h, w, c}, {w * c * py::ssize_t(sizeof(float)), c * py::ssize_t(sizeof(float)),
                                        py::ssize_t(sizeof(float))},
                            owned->data(), free_when_done);
}

// A progress callback for native code running without the GIL: re-takes it
// to call `report`, and lets Ctrl-C through as a Python exception.
inline std::function<bool(double)> with_gil(std::function<bool(double)> report) {
  return [report = std::move(report)](double fraction) {
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C
    return report(fraction);
  };
}

}  // namespace tempera::py_bridge

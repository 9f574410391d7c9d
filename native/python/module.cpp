// tempera._native: a thin pybind11 layer over the core library. It converts
// numpy arrays, releases the GIL while native code runs and turns every C++
// error into a Python exception.
#include <pybind11/stl.h>

#include "bind_method.hpp"
#include "numpy_bridge.hpp"
#include "tempera/app/contact_sheet.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/app/process.hpp"
#include "tempera/app/segments.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

void register_exceptions(py::module_& m) {
  static py::exception<CancelledError> cancelled(m, "Cancelled", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const FileNotFoundError& e) {
      PyErr_SetString(PyExc_FileNotFoundError, e.what());
    } catch (const IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const ValueError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const CancelledError& e) {
      cancelled(e.what());
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError, "tempera: out of memory");
    }
  });
}

void bind_io(py::module_& m) {
  m.def(
      "read_image",
      [](const std::string& path, std::optional<std::vector<std::string>> channels) {
        Image image;
        {
          py::gil_scoped_release release;
          image = read_image(path, channels.value_or(std::vector<std::string>{}));
        }
        return py_bridge::to_numpy(std::move(image));
      },
      py::arg("path"), py::arg("channels") = py::none(),
      "Read an image as a float32 (H, W, C) array; `channels` selects channels by name.");
  m.def(
      "image_info",
      [](const std::string& path) {
        ImageFileInfo info;
        {
          py::gil_scoped_release release;
          info = inspect_image(path);
        }
        py::dict d;
        d["width"] = info.width;
        d["height"] = info.height;
        d["channels"] = info.channel_names;
        return d;
      },
      py::arg("path"), "Size and channel names of an image file, without reading its pixels.");
  m.def(
      "write_image",
      [](const std::string& path, const FloatArray& array, std::vector<std::string> channel_names) {
        ImageView view = py_bridge::view_of(array, "image");
        py::gil_scoped_release release;
        write_image(path, view, channel_names);
      },
      py::arg("path"), py::arg("image"), py::arg("channel_names") = std::vector<std::string>{},
      "Write an (H, W[, C]) array atomically; 8-bit formats are clamped to [0, 1].");
  m.def(
      "set_max_image_pixels", [](std::int64_t pixels) { set_max_image_pixels(pixels); }, py::arg("pixels"),
      "Images declaring more pixels than this are refused (OSError) before their pixels are read; "
      "default 50 Mpix or $TEMPERA_MAX_IMAGE_PIXELS.");
  m.def("max_image_pixels", &max_image_pixels, "The current image size limit in pixels.");
  m.def(
      "contact_sheet",
      [](const std::vector<FloatArray>& images, int columns, int gap, int margin, std::vector<float> background) {
        std::vector<ImageView> views;
        for (std::size_t i = 0; i < images.size(); ++i)
          views.push_back(py_bridge::view_of(images[i], concat("contact_sheet: image ", i)));
        Image sheet;
        {
          py::gil_scoped_release release;
          sheet = contact_sheet(views, ContactSheetLayout{columns, gap, margin, std::move(background)});
        }
        return py_bridge::to_numpy(std::move(sheet));
      },
      py::arg("images"), py::arg("columns"), py::arg("gap"), py::arg("margin"), py::arg("background"),
      "Grid of images; use tempera.app.contact_sheet.contact_sheet.");
  m.def(
      "encode_video",
      [](const std::string& pattern, int first_frame, double fps, const std::string& out) {
        py::gil_scoped_release release;
        return encode_video(pattern, first_frame, fps, out);
      },
      py::arg("pattern"), py::arg("first_frame"), py::arg("fps"), py::arg("out"),
      "H.264 MP4 of numbered frames with ffmpeg, atomically; False (no file) without ffmpeg; use tempera.app.video.");
  m.def(
      "key_segments",
      [](const std::vector<int>& frames, const std::vector<int>& key_frames) {
        py::list out;
        for (const Segment& s : key_segments(frames, key_frames)) out.append(py::make_tuple(s.first, s.last, s.writes));
        return out;
      },
      py::arg("frames"), py::arg("key_frames"),
      "The job core's segments of a shot of consecutive frames (app/segments.hpp): [(first, last, frames it "
      "writes), ...] from key to key and to the shot's ends.");
}

}  // namespace

void bind_registry(py::module_& m);   // bind_registry.cpp
void bind_synthesis(py::module_& m);  // bind_synthesis.cpp
void bind_guides(py::module_& m);     // bind_guides.cpp
void bind_tracer(py::module_& m);     // bind_tracer.cpp

std::map<std::string, py_bridge::BindMethod>& py_bridge::method_bindings() {
  static std::map<std::string, BindMethod> bindings;  // made at first use: static init order is unknown
  return bindings;
}

PYBIND11_MODULE(_native, m) {
  m.doc() = "Tempera native engine";
  m.attr("__version__") = TEMPERA_VERSION;
  register_exceptions(m);
  bind_io(m);
  bind_registry(m);  // FrameJob, the base of the jobs bound after it
  bind_synthesis(m);
  bind_guides(m);
  bind_tracer(m);
  for (const auto& [name, bind] : py_bridge::method_bindings()) bind(m);  // each method's folder (bind_method.hpp)
}

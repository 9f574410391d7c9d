// Python binding of the light-path-expression tracer. The scene arrives as a
// typed tempera._native.Scene (bind_scene.cpp); tempera.tracer.lpe builds it from
// the scene dict, strictly: a missing or unknown key is a ValueError naming
// it, so an exporter typo never silently changes a render.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bind_options.hpp"
#include "numpy_bridge.hpp"
#include "tempera/tracer/embree_tracer.hpp"
#include "tempera/tracer/lpe.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

constexpr const char* kTraceDoc = R"(Render light-path-expression guides by path tracing (Embree).

trace_lpe(scene: Scene, expressions, options: TraceOptions, progress=None) -> (images, alpha)

images: one float32 (H, W, 3) linear radiance array per expression, in order;
alpha: float32 (H, W), the fraction of camera rays that hit geometry.
Expressions are written light-to-eye (LDE, LSE, L.*DDE, LD{1,2}E, ...).
The result depends on options.seed only, not on threads; TraceOptions.table()
lists every option (Cycles' bounce limits, caustics, Filter Glossy, pixel
filter). progress(fraction) returning False cancels with tempera.Cancelled.
The GIL is released while tracing.

scene: a tempera._native.Scene; tempera.trace_lpe also takes the scene dict
(unknown or missing keys raise ValueError naming them):
  vertices            float32 (V, 3) world space
  triangles           int (T, 3) vertex indices, counter-clockwise front faces
  triangle_materials  int (T,) index into materials
  normals             optional float32 (T, 3, 3) per-corner shading normals
  uvs                 optional float32 (T, 3, 2) per-corner UVs, origin bottom-left
  materials           list of dicts: base_color (3,) required; optional metallic 0,
                      specular 0.5, roughness 0.5, transmission 0, ior 1.45,
                      emission (3,) 0 (radiance W/m^2/sr, strength included),
                      base_color_texture float32 (H, W, 3) linear (replaces base_color);
                      or "closures": a list of Cycles closures (docs/lpe_guides.md)
  lights              optional list of dicts, by "type":
                      point: position, intensity (W/sr), radius 0
                      spot:  position, direction (unit, where it shines), intensity,
                             spot_half_angle (rad), radius 0, spot_blend 0
                      sun:   direction (unit, towards the sun), irradiance (W/m^2),
                             angle 0 (angular diameter, rad)
                      area:  center, axis_u, axis_v, normal (unit; emits along +normal
                             only), size_u, size_v (full sizes, disk: diameters),
                             radiance (W/m^2/sr), shape "rect" or "disk" ("rect")
  world               optional {"radiance": (3,), "map": texture index, "rotation": (3, 3)}:
                      constant W/m^2/sr, times an equirectangular map if given
  textures            optional list of float32 (H, W, 4) linear RGBA images (row 0 top)
  triangle_visibility optional int (T,) ray visibility bits (camera 1, diffuse 2,
                      glossy 4, transmission 8, shadow 16)
  camera              type "perspective" | "orthographic", camera_to_world (4, 4)
                      (looks down local -Z, +Y up), width, height (pixels),
                      tan_half_fov_x, tan_half_fov_y (perspective), ortho_width,
                      ortho_height (orthographic), shift_x 0, shift_y 0 (units of
                      the larger image side), clip_start 0.1, clip_end 1000.
)";

}  // namespace

void bind_scene_types(py::module_& m);  // bind_scene.cpp

void bind_tracer(py::module_& m) {
  bind_scene_types(m);
  py_bridge::bind_options_class<TraceOptions>(m, "TraceOptions", trace_option_table(),
                                              "Options of the tracer (native/include/tempera/tracer/embree_tracer.hpp).");
  m.def(
      "trace_lpe",
      [](const Scene& scene, const std::vector<std::string>& expressions, const TraceOptions& options,
         std::function<bool(double)> progress) {
        TraceProgress callback = py_bridge::with_gil([&](double fraction) {
          return progress ? progress(fraction) : true;
        });
        TraceResult result;
        {
          py::gil_scoped_release release;
          result = trace_lpe(scene, expressions, options, callback);
        }
        py::list images;
        for (auto& image : result.images) images.append(py_bridge::to_numpy(std::move(image)));
        const int h = result.alpha.height(), w = result.alpha.width();
        py::object alpha = py_bridge::to_numpy(std::move(result.alpha)).attr("reshape")(h, w);
        return py::make_tuple(images, alpha);
      },
      py::arg("scene"), py::arg("expressions"), py::arg("options"), py::arg("progress") = nullptr, kTraceDoc);
  m.def(
      "check_lpe", [](const std::string& expression) { compile_lpe(expression); }, py::arg("expression"),
      "Raise ValueError (with the 0-based position) if the light path expression is malformed.");
  m.def(
      "lpe_matches",
      [](const std::string& expression, const std::string& events) {
        return lpe_matches(compile_lpe(expression), events);
      },
      py::arg("expression"), py::arg("events"),
      "Whether the light-to-eye event string (e.g. 'LDDE') is matched by the expression.");
}

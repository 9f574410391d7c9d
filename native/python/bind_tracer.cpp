// Python binding of the light-path-expression tracer. The scene arrives as a
// dict of numpy arrays and plain values (format in trace_lpe's docstring and
// docs/lpe_guides.md); it is read strictly: a missing or unknown key is a
// ValueError naming it, so an exporter typo never silently changes a render.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <set>

#include "numpy_bridge.hpp"
#include "tempera/embree_tracer.hpp"
#include "tempera/lpe.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

// Reads one dict, remembering which keys were used; finish() rejects the rest.
class DictReader {
 public:
  DictReader(const py::handle& object, std::string what) : what_(std::move(what)) {
    if (!py::isinstance<py::dict>(object)) throw ValueError(what_ + " must be a dict");
    dict_ = py::reinterpret_borrow<py::dict>(object);
  }
  const std::string& what() const { return what_; }
  bool has(const char* key) const { return dict_.contains(key); }
  py::object required(const char* key) {
    if (!dict_.contains(key)) throw ValueError(concat(what_, ": missing key '", key, "'"));
    used_.insert(key);
    return dict_[key];
  }
  float number(const char* key) { return cast<float>(required(key), key); }
  float number(const char* key, float fallback) { return has(key) ? number(key) : fallback; }
  int integer(const char* key) { return cast<int>(required(key), key); }
  std::string text(const char* key) { return cast<std::string>(required(key), key); }
  Float3 float3(const char* key) {
    const FloatArray a = array(required(key), key);
    if (a.size() != 3) throw ValueError(concat(what_, " '", key, "' must have 3 values, got ", a.size()));
    return {a.data()[0], a.data()[1], a.data()[2]};
  }
  Float3 float3(const char* key, Float3 fallback) { return has(key) ? float3(key) : fallback; }
  FloatArray array(const py::object& value, const char* key) const {
    try {
      return value.cast<FloatArray>();
    } catch (const py::cast_error&) {
      throw ValueError(concat(what_, " '", key, "' must be numeric"));
    }
  }
  void finish() const {
    std::string unknown;
    for (const auto& [key, value] : dict_) {
      const std::string k = py::str(key);
      if (!used_.count(k)) unknown += (unknown.empty() ? "'" : ", '") + k + "'";
    }
    if (!unknown.empty()) throw ValueError(concat(what_, ": unknown keys ", unknown));
  }

 private:
  template <typename T>
  T cast(const py::object& value, const char* key) const {
    try {
      return value.cast<T>();
    } catch (const py::cast_error&) {
      throw ValueError(concat(what_, " '", key, "' has the wrong type"));
    }
  }

  std::string what_;
  py::dict dict_;
  std::set<std::string> used_;
};

// A float array of exactly `shape` (-1: any length), returned flat.
FloatArray shaped(DictReader& r, const char* key, std::vector<py::ssize_t> shape) {
  FloatArray a = r.array(r.required(key), key);
  bool ok = a.ndim() == py::ssize_t(shape.size());
  for (std::size_t i = 0; ok && i < shape.size(); ++i) {
    if (shape[i] < 0) shape[i] = a.shape(i);
    ok = a.shape(i) == shape[i];
  }
  if (!ok) {
    std::string want = "(";
    for (std::size_t i = 0; i < shape.size(); ++i) want += (i ? ", " : "") + std::to_string(shape[i]);
    std::string got = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) got += (i ? ", " : "") + std::to_string(a.shape(i));
    throw ValueError(concat(r.what(), " '", key, "' must have shape ", want, "), got ", got, ")"));
  }
  return a;
}

py::array_t<std::int64_t> integer_array(DictReader& r, const char* key) {
  py::array a = py::array::ensure(r.required(key));
  if (!a || (a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
    throw ValueError(concat(r.what(), " '", key, "' must be an integer array"));
  return a.cast<py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>>();
}

TextureRef parse_texture_ref(const py::handle& object, const std::string& what) {
  DictReader r(object, what);
  TextureRef t;
  t.image = r.integer("image");
  if (t.image < 0) throw ValueError(what + ": image must be >= 0");
  if (r.has("uv")) {
    const FloatArray uv = shaped(r, "uv", {2, 3});
    std::copy(uv.data(), uv.data() + 6, t.uv.begin());
  }
  t.channel = r.has("channel") ? r.integer("channel") : 4;
  r.finish();
  return t;
}

Factor parse_factor(const py::handle& object, const std::string& what) {
  DictReader r(object, what);
  Factor f;
  const std::string kind = r.text("kind");
  static const std::pair<const char*, Factor::Kind> kinds[] = {
      {"constant", Factor::Kind::constant}, {"texture", Factor::Kind::texture}, {"fresnel", Factor::Kind::fresnel},
      {"layer_fresnel", Factor::Kind::layer_fresnel}, {"layer_facing", Factor::Kind::layer_facing}};
  bool known = false;
  for (const auto& [name, k] : kinds)
    if (kind == name) f.kind = k, known = true;
  if (!known) throw ValueError(concat(what, ": unknown factor kind '", kind, "'"));
  f.value = r.number("value", 1);
  if (f.kind == Factor::Kind::texture) f.texture = parse_texture_ref(r.required("texture"), what + " texture");
  f.invert = r.has("invert") ? r.required("invert").cast<bool>() : false;
  r.finish();
  return f;
}

Closure parse_closure(const py::handle& object, const std::string& what) {
  DictReader r(object, what);
  Closure c;
  const std::string type = r.text("type");
  static const std::pair<const char*, Closure::Type> types[] = {
      {"principled", Closure::Type::principled}, {"diffuse", Closure::Type::diffuse},
      {"glossy", Closure::Type::glossy}, {"glass", Closure::Type::glass}, {"refraction", Closure::Type::refraction},
      {"translucent", Closure::Type::translucent}, {"transparent", Closure::Type::transparent},
      {"emission", Closure::Type::emission}};
  bool known = false;
  for (const auto& [name, t] : types)
    if (type == name) c.type = t, known = true;
  if (!known) throw ValueError(concat(what, ": unknown closure type '", type, "'"));
  c.weight = r.float3("weight", c.weight);
  c.color = r.float3("color", c.color);
  if (r.has("color_texture")) c.color_texture = parse_texture_ref(r.required("color_texture"), what + " color_texture");
  c.roughness = r.number("roughness", c.roughness);
  if (r.has("roughness_texture"))
    c.roughness_texture = parse_texture_ref(r.required("roughness_texture"), what + " roughness_texture");
  c.ior = r.number("ior", c.ior);
  c.metallic = r.number("metallic", c.metallic);
  c.specular = r.number("specular", c.specular);
  c.transmission = r.number("transmission", c.transmission);
  if (r.has("distribution")) {
    const std::string d = r.text("distribution");
    if (d == "ggx") c.distribution = Closure::Distribution::ggx;
    else if (d == "beckmann") c.distribution = Closure::Distribution::beckmann;
    else if (d == "sharp") c.distribution = Closure::Distribution::sharp;
    else throw ValueError(concat(what, ": distribution must be 'ggx', 'beckmann' or 'sharp', got '", d, "'"));
  }
  if (r.has("factors")) {
    const py::object factors = r.required("factors");
    if (!py::isinstance<py::list>(factors)) throw ValueError(what + " 'factors' must be a list");
    for (const auto& f : factors) c.factors.push_back(parse_factor(f, concat(what, " factor ", c.factors.size())));
  }
  r.finish();
  return c;
}

Material parse_material(const py::handle& object, std::size_t index) {
  DictReader r(object, concat("scene material ", index));
  Material m;
  if (r.has("closures")) {
    const py::object closures = r.required("closures");
    if (!py::isinstance<py::list>(closures)) throw ValueError(r.what() + " 'closures' must be a list");
    for (const auto& c : closures)
      m.closures.push_back(parse_closure(c, concat(r.what(), " closure ", m.closures.size())));
    m.base_color = r.float3("base_color", m.base_color);
  } else {
    m.base_color = r.float3("base_color");
  }
  m.metallic = r.number("metallic", m.metallic);
  m.specular = r.number("specular", m.specular);
  m.roughness = r.number("roughness", m.roughness);
  m.transmission = r.number("transmission", m.transmission);
  m.ior = r.number("ior", m.ior);
  m.emission = r.float3("emission", m.emission);
  if (r.has("base_color_texture")) {
    const FloatArray tex = shaped(r, "base_color_texture", {-1, -1, 3});
    m.base_color_texture = Image::copy_of(py_bridge::view_of(tex, r.what() + " base_color_texture"));
  }
  r.finish();
  return m;
}

Light parse_light(const py::handle& object, std::size_t index) {
  DictReader r(object, concat("scene light ", index));
  Light l;
  const std::string type = r.text("type");
  if (type == "point" || type == "spot") {
    l.type = type == "point" ? Light::Type::point : Light::Type::spot;
    l.position = r.float3("position");
    l.intensity = r.float3("intensity");
    l.radius = r.number("radius", 0);
    if (l.type == Light::Type::spot) {
      l.direction = r.float3("direction");
      l.spot_half_angle = r.number("spot_half_angle");
      l.spot_blend = r.number("spot_blend", 0);
    }
  } else if (type == "sun") {
    l.type = Light::Type::sun;
    l.direction = r.float3("direction");
    l.irradiance = r.float3("irradiance");
    l.angle = r.number("angle", 0);
  } else if (type == "area") {
    l.type = Light::Type::area;
    l.center = r.float3("center");
    l.axis_u = r.float3("axis_u");
    l.axis_v = r.float3("axis_v");
    l.normal = r.float3("normal");
    l.size_u = r.number("size_u");
    l.size_v = r.number("size_v");
    l.radiance = r.float3("radiance");
    const std::string shape = r.has("shape") ? r.text("shape") : "rect";
    if (shape != "rect" && shape != "disk")
      throw ValueError(concat(r.what(), ": shape must be 'rect' or 'disk', got '", shape, "'"));
    l.shape = shape == "rect" ? Light::Shape::rect : Light::Shape::disk;
  } else {
    throw ValueError(concat(r.what(), ": type must be 'point', 'spot', 'sun' or 'area', got '", type, "'"));
  }
  if (r.has("soft_shape")) {
    const std::string shape = r.text("soft_shape");
    if (shape != "disk" && shape != "sphere")
      throw ValueError(concat(r.what(), ": soft_shape must be 'disk' or 'sphere', got '", shape, "'"));
    l.soft_shape = shape == "disk" ? Light::SoftShape::disk : Light::SoftShape::sphere;
  }
  if (r.has("visibility")) l.visibility = unsigned(r.integer("visibility"));
  if (r.has("cast_shadow")) l.cast_shadow = r.required("cast_shadow").cast<bool>();
  r.finish();
  return l;
}

Camera parse_camera(const py::handle& object) {
  DictReader r(object, "scene camera");
  Camera c;
  const std::string type = r.text("type");
  if (type != "perspective" && type != "orthographic")
    throw ValueError(concat("scene camera: type must be 'perspective' or 'orthographic', got '", type, "'"));
  c.type = type == "perspective" ? Camera::Type::perspective : Camera::Type::orthographic;
  const FloatArray m = shaped(r, "camera_to_world", {4, 4});
  std::copy(m.data(), m.data() + 16, c.camera_to_world.begin());
  c.width = r.integer("width");
  c.height = r.integer("height");
  const bool perspective = c.type == Camera::Type::perspective;
  // Only the projection's own sizes are required; the other's may be present.
  c.tan_half_fov_x = perspective ? r.number("tan_half_fov_x") : r.number("tan_half_fov_x", 1);
  c.tan_half_fov_y = perspective ? r.number("tan_half_fov_y") : r.number("tan_half_fov_y", 1);
  c.ortho_width = perspective ? r.number("ortho_width", 1) : r.number("ortho_width");
  c.ortho_height = perspective ? r.number("ortho_height", 1) : r.number("ortho_height");
  c.shift_x = r.number("shift_x", 0);
  c.shift_y = r.number("shift_y", 0);
  c.clip_start = r.number("clip_start", c.clip_start);
  c.clip_end = r.number("clip_end", c.clip_end);
  r.finish();
  return c;
}

Scene parse_scene(const py::handle& object) {
  DictReader r(object, "scene");
  Scene s;
  const FloatArray vertices = shaped(r, "vertices", {-1, 3});
  for (py::ssize_t i = 0; i < vertices.shape(0); ++i)
    s.vertices.push_back({vertices.at(i, 0), vertices.at(i, 1), vertices.at(i, 2)});
  const auto triangles = integer_array(r, "triangles");
  if (triangles.ndim() != 2 || triangles.shape(1) != 3) throw ValueError("scene 'triangles' must have shape (T, 3)");
  const py::ssize_t count = triangles.shape(0);
  for (py::ssize_t t = 0; t < count; ++t) {
    std::array<std::uint32_t, 3> tri;
    for (int c = 0; c < 3; ++c) {
      const std::int64_t v = triangles.at(t, c);
      if (v < 0 || v >= std::int64_t(s.vertices.size()))
        throw ValueError(concat("scene: triangle ", t, " uses vertex ", v, " but there are only ", s.vertices.size(),
                                " vertices"));
      tri[c] = std::uint32_t(v);
    }
    s.triangles.push_back(tri);
  }
  const auto materials_of = integer_array(r, "triangle_materials");
  if (materials_of.ndim() != 1 || materials_of.shape(0) != count)
    throw ValueError(concat("scene 'triangle_materials' must have shape (", count, ",)"));
  for (py::ssize_t t = 0; t < count; ++t)
    s.triangle_materials.push_back(std::int32_t(std::clamp<std::int64_t>(materials_of.at(t), -1, INT32_MAX)));
  if (r.has("normals")) {
    const FloatArray n = shaped(r, "normals", {count, 3, 3});
    for (py::ssize_t i = 0; i < 3 * count; ++i) s.normals.push_back({n.data()[3 * i], n.data()[3 * i + 1], n.data()[3 * i + 2]});
  }
  if (r.has("uvs")) {
    const FloatArray uv = shaped(r, "uvs", {count, 3, 2});
    for (py::ssize_t i = 0; i < 3 * count; ++i) s.uvs.push_back({uv.data()[2 * i], uv.data()[2 * i + 1]});
  }
  const py::object materials = r.required("materials");
  if (!py::isinstance<py::list>(materials)) throw ValueError("scene 'materials' must be a list of dicts");
  for (const auto& m : materials) s.materials.push_back(parse_material(m, s.materials.size()));
  if (r.has("lights")) {
    const py::object lights = r.required("lights");
    if (!py::isinstance<py::list>(lights)) throw ValueError("scene 'lights' must be a list of dicts");
    for (const auto& l : lights) s.lights.push_back(parse_light(l, s.lights.size()));
  }
  if (r.has("textures")) {
    const py::object textures = r.required("textures");
    if (!py::isinstance<py::list>(textures)) throw ValueError("scene 'textures' must be a list of arrays");
    for (const auto& t : textures) {
      const std::string what = concat("scene texture ", s.textures.size());
      FloatArray a;
      try {
        a = t.cast<FloatArray>();
      } catch (const py::cast_error&) {
        throw ValueError(what + " must be numeric");
      }
      if (a.ndim() != 3 || a.shape(2) != 4) throw ValueError(what + " must have shape (H, W, 4)");
      s.textures.push_back(Image::copy_of(py_bridge::view_of(a, what)));
    }
  }
  if (r.has("world")) {
    DictReader w(r.required("world"), "scene world");
    s.world_radiance = w.float3("radiance");
    if (w.has("map")) s.world_map = w.integer("map");
    if (w.has("rotation")) {
      const FloatArray m = shaped(w, "rotation", {3, 3});
      std::copy(m.data(), m.data() + 9, s.world_rotation.begin());
    }
    w.finish();
  }
  if (r.has("triangle_visibility")) {
    const auto v = integer_array(r, "triangle_visibility");
    if (v.ndim() != 1 || v.shape(0) != count)
      throw ValueError(concat("scene 'triangle_visibility' must have shape (", count, ",)"));
    for (py::ssize_t t = 0; t < count; ++t) s.triangle_visibility.push_back(std::uint8_t(v.at(t) & 0xFF));
  }
  s.camera = parse_camera(r.required("camera"));
  r.finish();
  return s;
}

constexpr const char* kTraceDoc = R"(Render light-path-expression guides by path tracing (Embree).

trace_lpe(scene, expressions, samples=64, seed=0, threads=0, max_bounces=8,
          progress=None) -> (images, alpha)

images: one float32 (H, W, 3) linear radiance array per expression, in order;
alpha: float32 (H, W), the fraction of camera rays that hit geometry.
Expressions are written light-to-eye (LDE, LSE, L.*DDE, LD{1,2}E, ...).
The result depends on seed only, not on threads. max_bounces counts indirect
bounces like Cycles (0: direct light only). progress(fraction) returning False
cancels with tempera.Cancelled. The GIL is released while tracing.

scene: a dict (unknown or missing keys raise ValueError naming them):
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

void bind_tracer(py::module_& m) {
  m.def(
      "trace_lpe",
      [](const py::dict& scene_dict, const std::vector<std::string>& expressions, int samples, std::uint64_t seed,
         int threads, int max_bounces, std::function<bool(double)> progress, int diffuse_bounces, int glossy_bounces,
         int transmission_bounces, int transparent_bounces, bool caustics_reflective, bool caustics_refractive) {
        const Scene scene = parse_scene(scene_dict);
        TraceOptions options;
        options.samples = samples;
        options.seed = seed;
        options.threads = threads;
        options.max_bounces = max_bounces;
        options.diffuse_bounces = diffuse_bounces;
        options.glossy_bounces = glossy_bounces;
        options.transmission_bounces = transmission_bounces;
        options.transparent_bounces = transparent_bounces;
        options.caustics_reflective = caustics_reflective;
        options.caustics_refractive = caustics_refractive;
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
      py::arg("scene"), py::arg("expressions"), py::arg("samples") = 64, py::arg("seed") = 0, py::arg("threads") = 0,
      py::arg("max_bounces") = 8, py::arg("progress") = nullptr, py::arg("diffuse_bounces") = 1024,
      py::arg("glossy_bounces") = 1024, py::arg("transmission_bounces") = 1024, py::arg("transparent_bounces") = 1024,
      py::arg("caustics_reflective") = true, py::arg("caustics_refractive") = true, kTraceDoc);
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

// The tracer's scene types (tempera/tracer/scene.hpp) as Python classes, field by
// field: names and defaults have one source, the C++ structs. Vectors are
// set and read as tuples (Float3) or numpy arrays (geometry, images);
// lists of materials, closures and lights are copied in and out whole
// (`scene.materials = [...]`, not `scene.materials.append`).
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "numpy_bridge.hpp"
#include "tempera/tracer/scene.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

Float3 to_float3(const py::handle& value, const char* what) {
  FloatArray a;
  try {
    a = py::reinterpret_borrow<py::object>(value).cast<FloatArray>();
  } catch (const py::cast_error&) {
    throw ValueError(concat(what, " must be numeric"));
  }
  if (a.size() != 3) throw ValueError(concat(what, " must have 3 values, got ", a.size()));
  return {a.data()[0], a.data()[1], a.data()[2]};
}

py::tuple from_float3(Float3 v) { return py::make_tuple(v.x, v.y, v.z); }

// A Float3 field as a property taking any 3 numbers.
template <typename C>
void float3_field(py::class_<C>& cls, const char* name, Float3 C::*member) {
  cls.def_property(
      name, [member](const C& c) { return from_float3(c.*member); },
      [member, name](C& c, const py::object& v) { c.*member = to_float3(v, name); });
}

// A float array of exactly `shape` (-1: any length).
FloatArray shaped(const py::handle& value, std::vector<py::ssize_t> shape, const char* what) {
  FloatArray a;
  try {
    a = py::reinterpret_borrow<py::object>(value).cast<FloatArray>();
  } catch (const py::cast_error&) {
    throw ValueError(concat(what, " must be numeric"));
  }
  bool ok = a.ndim() == py::ssize_t(shape.size());
  for (std::size_t i = 0; ok && i < shape.size(); ++i) {
    if (shape[i] < 0) shape[i] = a.shape(i);
    ok = a.shape(i) == shape[i];
  }
  if (!ok) {
    std::string want = "(", got = "(";
    for (std::size_t i = 0; i < shape.size(); ++i) want += (i ? ", " : "") + std::to_string(shape[i]);
    for (py::ssize_t i = 0; i < a.ndim(); ++i) got += (i ? ", " : "") + std::to_string(a.shape(i));
    throw ValueError(concat(what, " must have shape ", want, "), got ", got, ")"));
  }
  return a;
}

py::array_t<std::int64_t> integers(const py::handle& value, const char* what) {
  py::array a = py::array::ensure(value);
  if (!a || (a.size() && a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
    throw ValueError(concat(what, " must be an integer array"));
  return a.cast<py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>>();
}

py::array_t<float> image_to_numpy(const Image& image) {
  Image copy = Image::copy_of(image.view());
  return py_bridge::to_numpy(std::move(copy));
}

Image image_from_numpy(const py::handle& value, int channels, const char* what) {
  const FloatArray a = shaped(value, {-1, -1, channels}, what);
  return Image::copy_of(py_bridge::view_of(a, what));
}

template <typename T>
py::array_t<float> rows_to_numpy(const std::vector<T>& rows, std::vector<py::ssize_t> shape, int per_row) {
  py::array_t<float> out(shape);
  float* p = out.mutable_data();
  for (const T& r : rows)
    for (int k = 0; k < per_row; ++k) *p++ = r[k];
  return out;
}

}  // namespace

void bind_scene_types(py::module_& m) {
  py::class_<TextureRef> texture_ref(m, "TextureRef", "A texture lookup: Scene.textures[image] at the affine UV map uv.");
  texture_ref.def(py::init<>())
      .def_readwrite("image", &TextureRef::image, "index into Scene.textures; -1: none")
      .def_readwrite("uv", &TextureRef::uv, "(u', v') = (uv[0] u + uv[1] v + uv[2], uv[3] u + uv[4] v + uv[5])")
      .def_readwrite("channel", &TextureRef::channel, "scalars: 0..3 = R, G, B, A; 4 = luminance");

  py::class_<Factor> factor(m, "Factor", "One factor of a closure's weight (Mix Shader fac), clamped to [0, 1].");
  py::enum_<Factor::Kind>(factor, "Kind")
      .value("constant", Factor::Kind::constant)
      .value("texture", Factor::Kind::texture)
      .value("fresnel", Factor::Kind::fresnel)
      .value("layer_fresnel", Factor::Kind::layer_fresnel)
      .value("layer_facing", Factor::Kind::layer_facing);
  factor.def(py::init<>())
      .def_readwrite("kind", &Factor::kind)
      .def_readwrite("value", &Factor::value, "constant: the value; fresnel: the IOR; layer_*: the blend")
      .def_readwrite("texture", &Factor::texture)
      .def_readwrite("invert", &Factor::invert, "the factor is 1 - x");

  py::class_<Closure> closure(m, "Closure", "A BSDF, emission or transparency of a Cycles shader.");
  py::enum_<Closure::Type>(closure, "Type")
      .value("principled", Closure::Type::principled)
      .value("diffuse", Closure::Type::diffuse)
      .value("glossy", Closure::Type::glossy)
      .value("glass", Closure::Type::glass)
      .value("refraction", Closure::Type::refraction)
      .value("translucent", Closure::Type::translucent)
      .value("transparent", Closure::Type::transparent)
      .value("emission", Closure::Type::emission);
  py::enum_<Closure::Distribution>(closure, "Distribution")
      .value("ggx", Closure::Distribution::ggx)
      .value("beckmann", Closure::Distribution::beckmann)
      .value("sharp", Closure::Distribution::sharp);
  closure.def(py::init<>())
      .def_readwrite("type", &Closure::type)
      .def_readwrite("distribution", &Closure::distribution)
      .def_readwrite("factors", &Closure::factors)
      .def_readwrite("color_texture", &Closure::color_texture)
      .def_readwrite("roughness", &Closure::roughness)
      .def_readwrite("roughness_texture", &Closure::roughness_texture)
      .def_readwrite("ior", &Closure::ior)
      .def_readwrite("metallic", &Closure::metallic)
      .def_readwrite("specular", &Closure::specular)
      .def_readwrite("transmission", &Closure::transmission)
      .def_readwrite("subsurface", &Closure::subsurface)
      .def_readwrite("clearcoat", &Closure::clearcoat)
      .def_readwrite("clearcoat_roughness", &Closure::clearcoat_roughness)
      .def_readwrite("specular_ior_level", &Closure::specular_ior_level)
      .def_readwrite("coat_ior", &Closure::coat_ior)
      .def_readwrite("multiscatter", &Closure::multiscatter);
  float3_field(closure, "weight", &Closure::weight);
  float3_field(closure, "specular_tint", &Closure::specular_tint);
  float3_field(closure, "coat_tint", &Closure::coat_tint);
  float3_field(closure, "subsurface_color", &Closure::subsurface_color);
  float3_field(closure, "color", &Closure::color);

  py::class_<Material> material(m, "Material", "A surface: its closures, or the Principled-like fields if none.");
  material.def(py::init<>())
      .def_readwrite("metallic", &Material::metallic)
      .def_readwrite("specular", &Material::specular)
      .def_readwrite("roughness", &Material::roughness)
      .def_readwrite("transmission", &Material::transmission)
      .def_readwrite("ior", &Material::ior)
      .def_readwrite("closures", &Material::closures)
      .def_property(
          "base_color_texture",
          [](const Material& mat) -> py::object {
            return mat.base_color_texture.empty() ? py::object(py::none()) : image_to_numpy(mat.base_color_texture);
          },
          [](Material& mat, const py::object& v) {
            mat.base_color_texture = v.is_none() ? Image() : image_from_numpy(v, 3, "base_color_texture");
          });
  float3_field(material, "base_color", &Material::base_color);
  float3_field(material, "emission", &Material::emission);

  py::class_<Light> light(m, "Light", "A light in physical units (docs/lpe_guides.md).");
  py::enum_<Light::Type>(light, "Type")
      .value("point", Light::Type::point)
      .value("spot", Light::Type::spot)
      .value("sun", Light::Type::sun)
      .value("area", Light::Type::area);
  py::enum_<Light::Shape>(light, "Shape").value("rect", Light::Shape::rect).value("disk", Light::Shape::disk);
  py::enum_<Light::SoftShape>(light, "SoftShape")
      .value("disk", Light::SoftShape::disk)
      .value("sphere", Light::SoftShape::sphere);
  light.def(py::init<>())
      .def_readwrite("type", &Light::type)
      .def_readwrite("shape", &Light::shape)
      .def_readwrite("soft_shape", &Light::soft_shape)
      .def_readwrite("radius", &Light::radius)
      .def_readwrite("spot_half_angle", &Light::spot_half_angle)
      .def_readwrite("spot_blend", &Light::spot_blend)
      .def_readwrite("spot_axis_cosine", &Light::spot_axis_cosine)
      .def_readwrite("angle", &Light::angle)
      .def_readwrite("size_u", &Light::size_u)
      .def_readwrite("size_v", &Light::size_v)
      .def_readwrite("visibility", &Light::visibility)
      .def_readwrite("cast_shadow", &Light::cast_shadow)
      .def_readwrite("max_bounces", &Light::max_bounces, "bounces before a vertex that NEE lights (Cycles' Max Bounces)")
      .def_readwrite("multiple_importance", &Light::multiple_importance,
                     "BSDF rays hit the light, weighted by MIS (Cycles' Multiple Importance)");
  for (auto [name, member] : {std::pair{"position", &Light::position}, {"direction", &Light::direction},
                              {"intensity", &Light::intensity}, {"irradiance", &Light::irradiance},
                              {"center", &Light::center}, {"axis_u", &Light::axis_u}, {"axis_v", &Light::axis_v},
                              {"normal", &Light::normal}, {"radiance", &Light::radiance}})
    float3_field(light, name, member);

  py::class_<Camera> camera(m, "Camera", "A perspective or orthographic camera (docs/lpe_guides.md).");
  py::enum_<Camera::Type>(camera, "Type")
      .value("perspective", Camera::Type::perspective)
      .value("orthographic", Camera::Type::orthographic);
  camera.def(py::init<>())
      .def_readwrite("type", &Camera::type)
      .def_property(
          "camera_to_world",
          [](const Camera& c) {
            py::array_t<float> out({4, 4});
            std::copy(c.camera_to_world.begin(), c.camera_to_world.end(), out.mutable_data());
            return out;
          },
          [](Camera& c, const py::object& v) {
            const FloatArray a = shaped(v, {4, 4}, "camera_to_world");
            std::copy(a.data(), a.data() + 16, c.camera_to_world.begin());
          })
      .def_readwrite("width", &Camera::width)
      .def_readwrite("height", &Camera::height)
      .def_readwrite("tan_half_fov_x", &Camera::tan_half_fov_x)
      .def_readwrite("tan_half_fov_y", &Camera::tan_half_fov_y)
      .def_readwrite("shift_x", &Camera::shift_x)
      .def_readwrite("shift_y", &Camera::shift_y)
      .def_readwrite("ortho_width", &Camera::ortho_width)
      .def_readwrite("ortho_height", &Camera::ortho_height)
      .def_readwrite("clip_start", &Camera::clip_start)
      .def_readwrite("clip_end", &Camera::clip_end);

  py::class_<ClosureModel>(m, "ClosureModel", "Which Cycles' microfacet closures to render (3.x's by default).")
      .def(py::init<>())
      .def_readwrite("height_correlated_shadowing", &ClosureModel::height_correlated_shadowing,
                     "Smith shadowing 1 / (1 + Lambda(i) + Lambda(o)) (Cycles 4.0+) instead of G1(i) G1(o)")
      .def_readwrite("microfacet_glass_fresnel", &ClosureModel::microfacet_glass_fresnel,
                     "rough glass weighted by the Fresnel of each microfacet (Cycles 4.0+), not of the normal")
      .def_readwrite("principled_v2", &ClosureModel::principled_v2,
                     "Principled closures are Cycles 4.0's layered Principled v2, not 3.x's v1")
      .def_readwrite("energy_preserving_oren_nayar", &ClosureModel::energy_preserving_oren_nayar,
                     "Diffuse roughness is Cycles 4.3's Oren-Nayar with its multiple-scattering term");

  py::class_<Scene> scene(m, "Scene", "The tracer's scene: triangles, materials, lights, world and camera.");
  scene.def(py::init<>())
      .def_property(
          "vertices", [](const Scene& s) { return rows_to_numpy(s.vertices, {py::ssize_t(s.vertices.size()), 3}, 3); },
          [](Scene& s, const py::object& v) {
            const FloatArray a = shaped(v, {-1, 3}, "scene 'vertices'");
            s.vertices.resize(std::size_t(a.shape(0)));
            for (py::ssize_t i = 0; i < a.shape(0); ++i) s.vertices[std::size_t(i)] = {a.at(i, 0), a.at(i, 1), a.at(i, 2)};
          })
      .def_property(
          "triangles",
          [](const Scene& s) {
            py::array_t<std::uint32_t> out({py::ssize_t(s.triangles.size()), py::ssize_t(3)});
            std::memcpy(out.mutable_data(), s.triangles.data(), s.triangles.size() * 3 * sizeof(std::uint32_t));
            return out;
          },
          [](Scene& s, const py::object& v) {
            const auto a = integers(v, "scene 'triangles'");
            if (a.ndim() != 2 || a.shape(1) != 3) throw ValueError("scene 'triangles' must have shape (T, 3)");
            s.triangles.resize(std::size_t(a.shape(0)));
            for (py::ssize_t t = 0; t < a.shape(0); ++t)
              for (int c = 0; c < 3; ++c) {
                const std::int64_t i = a.at(t, c);
                if (i < 0 || i > std::int64_t(UINT32_MAX))
                  throw ValueError(concat("scene: triangle ", t, " uses vertex ", i, " but there are only ",
                                          s.vertices.size(), " vertices"));
                s.triangles[std::size_t(t)][c] = std::uint32_t(i);
              }
          })
      .def_property(
          "triangle_materials", [](const Scene& s) { return py::array_t<std::int32_t>(py::ssize_t(s.triangle_materials.size()), s.triangle_materials.data()); },
          [](Scene& s, const py::object& v) {
            const auto a = integers(v, "scene 'triangle_materials'");
            if (a.ndim() != 1) throw ValueError("scene 'triangle_materials' must have shape (T,)");
            s.triangle_materials.resize(std::size_t(a.shape(0)));
            for (py::ssize_t t = 0; t < a.shape(0); ++t)
              s.triangle_materials[std::size_t(t)] = std::int32_t(std::clamp<std::int64_t>(a.at(t), -1, INT32_MAX));
          })
      .def_property(
          "normals",
          [](const Scene& s) {
            return rows_to_numpy(s.normals, {py::ssize_t(s.normals.size() / 3), 3, 3}, 3);
          },
          [](Scene& s, const py::object& v) {
            const FloatArray a = shaped(v, {-1, 3, 3}, "scene 'normals'");
            s.normals.resize(std::size_t(3 * a.shape(0)));
            for (std::size_t i = 0; i < s.normals.size(); ++i)
              s.normals[i] = {a.data()[3 * i], a.data()[3 * i + 1], a.data()[3 * i + 2]};
          })
      .def_property(
          "uvs", [](const Scene& s) { return rows_to_numpy(s.uvs, {py::ssize_t(s.uvs.size() / 3), 3, 2}, 2); },
          [](Scene& s, const py::object& v) {
            const FloatArray a = shaped(v, {-1, 3, 2}, "scene 'uvs'");
            s.uvs.resize(std::size_t(3 * a.shape(0)));
            for (std::size_t i = 0; i < s.uvs.size(); ++i) s.uvs[i] = {a.data()[2 * i], a.data()[2 * i + 1]};
          })
      .def_property(
          "triangle_visibility",
          [](const Scene& s) { return py::array_t<std::uint8_t>(py::ssize_t(s.triangle_visibility.size()), s.triangle_visibility.data()); },
          [](Scene& s, const py::object& v) {
            const auto a = integers(v, "scene 'triangle_visibility'");
            if (a.ndim() != 1) throw ValueError("scene 'triangle_visibility' must have shape (T,)");
            s.triangle_visibility.resize(std::size_t(a.shape(0)));
            for (py::ssize_t t = 0; t < a.shape(0); ++t) s.triangle_visibility[std::size_t(t)] = std::uint8_t(a.at(t) & 0xFF);
          })
      .def_property(
          "textures",
          [](const Scene& s) {
            py::list out;
            for (const Image& t : s.textures) out.append(image_to_numpy(t));
            return out;
          },
          [](Scene& s, const py::list& v) {
            s.textures.clear();
            for (const auto& t : v) s.textures.push_back(image_from_numpy(t, 4, concat("scene texture ", s.textures.size()).c_str()));
          })
      .def_readwrite("materials", &Scene::materials)
      .def_readwrite("lights", &Scene::lights)
      .def_readwrite("world_map", &Scene::world_map, "index into textures of an equirectangular world; -1: none")
      .def_readwrite("world_rotation", &Scene::world_rotation, "row-major 3x3 turning world directions into the map's")
      .def_readwrite("world_visibility", &Scene::world_visibility, "bits of the rays that see the world")
      .def_readwrite("camera", &Scene::camera)
      .def_readwrite("closure_model", &Scene::closure_model)
      .def("validate", &validate_scene, "Raise ValueError naming the first problem of the scene.");
  float3_field(scene, "world_radiance", &Scene::world_radiance);
}

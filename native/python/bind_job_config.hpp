#pragma once
// Job configs as Python classes, field by field (issue 41, step 6). Each
// config struct is bound once, by the binding of its job (JobConfig with the
// job core's, bind_registry.cpp; a method's in its bind file), with
// ConfigClass: keyword construction that names every unknown keyword, an
// attribute per field whose setter names the field and what it expects
// ("frames expects a list of whole numbers, got '1-3'"), paths as str or
// os.PathLike, None for an optional field, enums by name, and a repr.
#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bind_options.hpp"
#include "tempera/app/job_config.hpp"
#include "tempera/app/light_path_guides.hpp"
#include "tempera/app/light_path_shot.hpp"
#include "tempera/engine/error.hpp"

namespace tempera::py_bridge {

namespace py = pybind11;

// `value` as a field of type T, or a ValueError naming the field and what it expects.
template <class T>
T field_value(const py::handle& value, const char* name) {
  if constexpr (is_optional<T>::value) {
    if (value.is_none()) return std::nullopt;
    return field_value<typename T::value_type>(value, name);
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (py::hasattr(value, "__fspath__")) return py::cast<std::string>(value.attr("__fspath__")());
    if (py::isinstance<py::str>(value)) return py::cast<std::string>(value);
  } else if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>) {
    try {
      return from_python<T>(value, name);
    } catch (const py::error_already_set&) {  // e.g. an int too large for C++
    }
  } else {
    try {
      if (!py::isinstance<py::str>(value)) return py::cast<T>(value);
    } catch (const py::cast_error&) {
    }
  }
  throw ValueError(concat(name, " expects ", kind_name<T>(), ", got ", std::string(py::repr(value)).substr(0, 80)));
}

template <class T>
struct is_container : std::false_type {};
template <class T>
struct is_container<std::vector<T>> : std::true_type {};
template <class A, class B>
struct is_container<std::pair<A, B>> : std::true_type {};

// A struct bound as its own Python class (an options class), not a value
// that pybind11 converts (a string, list, tuple or optional).
template <class T>
constexpr bool is_struct_field =
    std::is_class_v<T> && !std::is_same_v<T, std::string> && !is_optional<T>::value && !is_container<T>::value;

template <class T>
py::object field_python(const T& v) {
  if constexpr (is_optional<T>::value) return v ? field_python(*v) : py::none();
  else return to_python(v);
}

// A config struct S as a Python class, its fields added one by one.
template <class S>
class ConfigClass {
 public:
  ConfigClass(py::module_& m, const char* name, const char* doc) : cls_(m, name, doc) {
    cls_.def(py::init([setters = setters_, name](const py::kwargs& kw) {
      S s;
      std::string unknown;
      for (const auto& [key, value] : kw) {
        const std::string k = py::str(key);
        auto it = std::find_if(setters->begin(), setters->end(), [&](const auto& f) { return f.first == k; });
        if (it == setters->end()) unknown += (unknown.empty() ? "'" : ", '") + k + "'";
        else it->second(s, value);
      }
      if (!unknown.empty()) throw ValueError(concat("unknown ", name, " field(s) ", unknown, " (known: ", known(*setters), ")"));
      return s;
    }));
    cls_.def("__repr__", [setters = setters_, name](const py::object& self) {
      std::string out = std::string(name) + "(";
      for (const auto& [field, set] : *setters)
        out += (out.back() == '(' ? "" : ", ") + field + "=" + std::string(py::repr(self.attr(field.c_str())));
      return out + ")";
    });
  }

  template <class T, class C>
  ConfigClass& field(const char* name, T C::*member, const char* help) {
    static_assert(std::is_base_of_v<C, S>);
    const auto set = [member, name](S& s, const py::handle& v) { s.*member = field_value<T>(v, name); };
    if constexpr (is_struct_field<T>) {
      // Its attributes set in place: config.lines.weight = 2.
      return field_with(name, py::cpp_function([member](S& s) -> T& { return s.*member; },
                                               py::return_value_policy::reference_internal),
                        set, help);
    } else {
      return field_with(name, py::cpp_function([member](const S& s) { return field_python(s.*member); }), set, help);
    }
  }

  // A field read and set by `get` (a cpp_function taking S) and `set(S&, value)`.
  template <class Set>
  ConfigClass& field_with(const char* name, const py::cpp_function& get, Set set, const char* help) {
    setters_->emplace_back(name, set);
    cls_.def_property(name, get, [set](S& s, const py::object& v) { set(s, v); }, help);
    return *this;
  }

 private:
  using Setter = std::function<void(S&, const py::handle&)>;
  static std::string known(const std::vector<std::pair<std::string, Setter>>& setters) {
    std::string out;
    for (const auto& f : setters) out += (out.empty() ? "" : ", ") + f.first;
    return out;
  }

  py::class_<S> cls_;
  std::shared_ptr<std::vector<std::pair<std::string, Setter>>> setters_ =
      std::make_shared<std::vector<std::pair<std::string, Setter>>>();
};

// The job core's fields (app/job_config.hpp), first in every job config's class.
template <class S>
ConfigClass<S>& job_config_fields(ConfigClass<S>& c) {
  return c.field("exemplar", &JobConfig::exemplar, "the look: a painting, a medium, an RGBA image or a folder of frames")
      .field("guides", &JobConfig::guides, "the shot's guide cache folder")
      .field("frames", &JobConfig::frames, "the frames to make, in this order")
      .field("out", &JobConfig::out, "output folder")
      .field("format", &JobConfig::format, "png | exr")
      .field("resume", &JobConfig::resume, "skip what is current; False makes everything again");
}

// The exemplar render's fields of the light-path methods' configs (app/light_path_shot.hpp).
template <class S>
ConfigClass<S>& light_path_shot_fields(ConfigClass<S>& c) {
  return c.field("exemplar_guides", &LightPathShotConfig::exemplar_guides, "guide cache folder of the exemplar render")
      .field("exemplar_frame", &LightPathShotConfig::exemplar_frame, "frame of exemplar_guides (None: its only frame)")
      .field("prefix", &LightPathShotConfig::prefix, "the frames' file names: PREFIX0001.png");
}

// Light-path guide weights as a dict {guide: weight} in matching order.
inline py::dict guide_weights_dict(const GuideWeights& weights) {
  py::dict out;
  for (const auto& [name, weight] : weights) out[py::str(name)] = weight;
  return out;
}

// Sets the named guides' weights from a dict; the others keep theirs.
inline void set_guide_weights(GuideWeights& weights, const py::handle& values) {
  if (!py::isinstance<py::dict>(values))
    throw ValueError(concat("weights expects a dict {guide: weight}, got ", std::string(py::repr(values)).substr(0, 80)));
  for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(values)) {
    const std::string name = py::str(key);
    auto it = std::find_if(weights.begin(), weights.end(), [&](auto& w) { return w.first == name; });
    if (it == weights.end())
      throw ValueError(concat("unknown guide '", name, "' in weights (StyLit guides: ", light_path_guide_names(), ")"));
    it->second = field_value<float>(value, concat("weight of '", name, "'").c_str());
  }
}

// ValueError "`what` needs 'NAME'" for each of exemplar, frames and out that is empty.
inline void require_job_config(const JobConfig& c, const std::string& what) {
  if (c.exemplar.empty()) throw ValueError(concat(what, " needs 'exemplar'"));
  if (c.frames.empty()) throw ValueError(concat(what, " needs 'frames'"));
  if (c.out.empty()) throw ValueError(concat(what, " needs 'out'"));
}

// The same, and the exemplar render's guide cache of a light-path method's config.
inline void require_light_path_shot(const LightPathShotConfig& c, const std::string& what) {
  require_job_config(c, what);
  if (c.exemplar_guides.empty()) throw ValueError(concat(what, " needs 'exemplar_guides'"));
}

}  // namespace tempera::py_bridge

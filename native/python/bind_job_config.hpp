#pragma once
// Job configs as Python classes, field by field (issue 41, step 6). Each
// config struct is bound once, by the binding of its job (JobConfig with the
// job core's, bind_registry.cpp; a method's in its bind file), with
// ConfigClass: keyword construction that names every unknown keyword, an
// attribute per field whose setter names the field and what it expects
// ("frames expects a list of whole numbers, got '1-3'"), paths as str or
// os.PathLike, None for an optional field, enums by name, and a repr.
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
    setters_->emplace_back(name, [member, name](S& s, const py::handle& v) { s.*member = field_value<T>(v, name); });
    cls_.def_property(
        name, [member](const S& s) { return field_python(s.*member); },
        [member, name](S& s, const py::object& v) { s.*member = field_value<T>(v, name); }, help);
    return *this;
  }

  py::class_<S>& cls() { return cls_; }

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

// ValueError "`what` needs 'NAME'" for each of exemplar, frames and out that is empty.
inline void require_job_config(const JobConfig& c, const std::string& what) {
  if (c.exemplar.empty()) throw ValueError(concat(what, " needs 'exemplar'"));
  if (c.frames.empty()) throw ValueError(concat(what, " needs 'frames'"));
  if (c.out.empty()) throw ValueError(concat(what, " needs 'out'"));
}

// The former dict path (a config as a dict keyed by field names), until the
// last job takes its config class.
template <typename T>
constexpr const char* dict_kind_name() {
  if constexpr (std::is_same_v<T, std::string>) return "a string";
  else if constexpr (std::is_same_v<T, bool>) return "True or False";
  else if constexpr (std::is_integral_v<T>) return "a whole number";
  else if constexpr (std::is_floating_point_v<T>) return "a number";
  else if constexpr (std::is_same_v<T, std::vector<int>>) return "a list of whole numbers";
  else if constexpr (std::is_same_v<T, pybind11::dict>) return "a dict";
  else return "another type";
}

// d[key] as T, or a ValueError naming `what` and the key.
template <typename T>
T get(const pybind11::dict& d, const char* key, const std::string& what) {
  namespace py = pybind11;
  if (!d.contains(key)) throw ValueError(concat(what, " needs '", key, "'"));
  const py::object value = d[key];
  try {
    if constexpr (std::is_same_v<T, std::string>) {
      if (!py::isinstance<py::str>(value)) throw py::cast_error("");
    }
    return value.cast<T>();
  } catch (const py::cast_error&) {
  } catch (const py::error_already_set&) {  // e.g. an int too large for C++
  }
  throw ValueError(concat(what, " '", key, "' must be ", dict_kind_name<T>(), ", got ",
                          std::string(py::repr(value)).substr(0, 80)));
}

// True when d has `key` with a value other than None.
inline bool given(const pybind11::dict& d, const char* key) { return d.contains(key) && !d[key].is_none(); }

// exemplar, frames and out are required; guides, format and resume keep
// their defaults when absent or None.
inline void read_job_config(const pybind11::dict& d, JobConfig& c, const std::string& what) {
  c.exemplar = get<std::string>(d, "exemplar", what);
  c.frames = get<std::vector<int>>(d, "frames", what);
  c.out = get<std::string>(d, "out", what);
  if (given(d, "guides")) c.guides = get<std::string>(d, "guides", what);
  if (given(d, "format")) c.format = get<std::string>(d, "format", what);
  if (given(d, "resume")) c.resume = get<bool>(d, "resume", what);
}

}  // namespace tempera::py_bridge

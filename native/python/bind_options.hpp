#pragma once
// Options structs as Python classes, field by field from their tables
// (option_table.hpp): attributes with the C++ defaults, enums as their names,
// keyword construction that rejects unknown names, and the table itself for
// the add-on and the docs.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "tempera/engine/option_table.hpp"

namespace tempera::py_bridge {

namespace py = pybind11;

template <class T>
py::object to_python(const T& v) {
  if constexpr (std::is_enum_v<T>) return py::str(enum_name(v));
  else return py::cast(v);
}

template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};

// What a value of type T is, as messages say it.
template <class T>
std::string kind_name() {
  if constexpr (std::is_same_v<T, std::string>) return "a string or path";
  else if constexpr (std::is_same_v<T, bool>) return "True or False";
  else if constexpr (std::is_enum_v<T>) return "one of " + enum_choices<T>();
  else if constexpr (std::is_integral_v<T>) return "a whole number";
  else if constexpr (std::is_floating_point_v<T>) return "a number";
  else if constexpr (std::is_same_v<T, std::vector<int>>) return "a list of whole numbers";
  else if constexpr (is_optional<T>::value) return kind_name<typename T::value_type>() + " or None";
  else return py::type_id<T>();
}

template <class T>
T from_python(const py::handle& value, const char* name) {
  try {
    if constexpr (std::is_enum_v<T>) {
      return parse_enum<T>(py::cast<std::string>(value), EnumNames<T>::what);
    } else if constexpr (std::is_same_v<T, bool>) {
      if (!py::isinstance<py::bool_>(value) && !py::isinstance<py::int_>(value))
        throw ValueError(concat(name, " expects True or False"));
      return py::cast<bool>(value);
    } else if constexpr (std::is_integral_v<T>) {
      if (py::isinstance<py::float_>(value)) {
        const double d = py::cast<double>(value);
        if (d != std::floor(d)) throw ValueError(concat(name, " expects a whole number, got ", d));
      }
      return py::cast<T>(value);
    } else {
      return py::cast<T>(value);
    }
  } catch (const py::cast_error&) {
    throw ValueError(concat(name, " expects ", kind_name<T>(), ", got ", std::string(py::repr(value)).substr(0, 80)));
  }
}

// Sets `options` from a dict of keyword values; unknown keys are errors, so a
// typo never falls back to a default silently.
template <class S, class Tuple>
void set_from_dict(S& options, const Tuple& table, const py::dict& values, const char* what) {
  for (const auto& [key, value] : values) {
    const std::string k = py::cast<std::string>(key);
    bool found = false;
    for_each_field(table, [&](const auto& f) {
      using T = std::decay_t<decltype(options.*f.member)>;
      if (found || k != f.name) return;
      options.*f.member = from_python<T>(value, f.name);
      found = true;
    });
    if (!found) {
      std::string known;
      for_each_field(table, [&](const auto& f) { known += (known.empty() ? "" : ", ") + std::string(f.name); });
      throw ValueError(concat("unknown ", what, " '", k, "' (known: ", known, ")"));
    }
  }
}

// The table as a list of dicts: name, flag, help, default, min, max, choices.
template <class S, class Tuple>
py::list table_as_list(const Tuple& table) {
  const S defaults{};
  py::list out;
  for_each_field(table, [&](const auto& f) {
    using T = std::decay_t<decltype(defaults.*f.member)>;
    py::dict d;
    d["name"] = f.name;
    d["flag"] = f.flag;
    d["help"] = f.help;
    d["default"] = to_python(defaults.*f.member);
    d["min"] = f.min;
    d["max"] = f.max;
    py::list choices;
    if constexpr (std::is_enum_v<T>)
      for (const char* n : EnumNames<T>::names) choices.append(n);
    d["choices"] = choices;
    out.append(d);
  });
  return out;
}

template <class S, class Tuple>
py::class_<S> bind_options_class(py::module_& m, const char* name, const Tuple& table, const char* doc) {
  py::class_<S> cls(m, name, doc);
  cls.def(py::init([table](const py::kwargs& kw) {
    S s;
    set_from_dict(s, table, kw, "option");
    return s;
  }));
  for_each_field(table, [&](const auto& f) {
    using T = std::decay_t<decltype(std::declval<S>().*f.member)>;
    const auto member = f.member;
    const char* fname = f.name;
    cls.def_property(
        f.name, [member](const S& s) { return to_python(s.*member); },
        [member, fname](S& s, const py::object& v) { s.*member = from_python<T>(v, fname); }, f.help);
  });
  cls.def_static("table", [table]() { return table_as_list<S>(table); }, "The option table: name, flag, help, default, range.");
  cls.def("__repr__", [table, name](const S& s) {
    std::string out = std::string(name) + "(";
    bool first = true;
    for_each_field(table, [&](const auto& f) {
      out += (first ? "" : ", ") + std::string(f.name) + "=" + format_value(s.*f.member);
      first = false;
    });
    return out + ")";
  });
  return cls;
}

}  // namespace tempera::py_bridge

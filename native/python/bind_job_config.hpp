#pragma once
// A job's config from Python, read one way for every method: a dict whose
// keys are the config's field names. read_job_config reads the job core's
// JobConfig fields (app/job_config.hpp); a job's binding reads its own after.
// A value of the wrong type is a ValueError naming the key ("StylizeJob
// config 'frames' must be a list of whole numbers, got 'x'"), not pybind11's
// anonymous "Unable to cast Python instance".
#include <string>
#include <type_traits>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "tempera/app/job_config.hpp"
#include "tempera/engine/error.hpp"

namespace tempera::py_bridge {

template <typename T>
constexpr const char* kind_name() {
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
  throw ValueError(concat(what, " '", key, "' must be ", kind_name<T>(), ", got ",
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

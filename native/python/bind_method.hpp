#pragma once
// A method's binding registers itself, so that a method's folder holds it
// (native/src/methods/NAME/bind_NAME.cpp, compiled only into the module)
// and nothing outside the folder names it: module.cpp runs the core's
// bindings first (FrameJob, which the jobs derive from; the engine's
// options; guides; the tracer), then every registered method's, in name
// order.
#include <map>
#include <string>

#include <pybind11/pybind11.h>

namespace tempera::py_bridge {

using BindMethod = void (*)(pybind11::module_&);

// Every method's binding by name (filled before the module initializes).
std::map<std::string, BindMethod>& method_bindings();

// `const MethodBinding kBinding("NAME", bind_NAME);` at namespace
// scope in the method's bind file registers it.
struct MethodBinding {
  MethodBinding(const std::string& name, BindMethod bind) { method_bindings().emplace(name, bind); }
};

}  // namespace tempera::py_bridge

#pragma once
// Error types of the native engine. Every failure the user can cause (bad
// input, unreadable file, cancelled run) is one of these; the Python layer
// maps each to a Python exception so that nothing ever aborts the process.
#include <stdexcept>
#include <string>

namespace tempera {

// Invalid arguments: wrong sizes, NaNs, empty masks, unknown options.
struct ValueError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// A file could not be read or written; the message names the file.
struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct FileNotFoundError : IoError {
  using IoError::IoError;
};

// A long computation was stopped by its cancel callback.
struct CancelledError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// printf-free message building: concat("bad size ", w, "x", h).
template <typename... Parts>
std::string concat(const Parts&... parts);

}  // namespace tempera

#include <sstream>
template <typename... Parts>
std::string tempera::concat(const Parts&... parts) {
  std::ostringstream out;
  (out << ... << parts);
  return out.str();
}

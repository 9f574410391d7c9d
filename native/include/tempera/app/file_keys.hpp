#pragma once
// Names and resume keys of the files that jobs write (the stylize job, the
// noisy command).
#include <string>

namespace tempera {

// "<prefix>0001.<extension>".
std::string frame_file(const std::string& prefix, int frame, const std::string& extension);

// FNV-1a, 64 bits, as 16 hex digits: stable across runs and builds (std::hash is not).
std::string hash_hex(const std::string& text);

// Size and modification time: a changed file changes a key without hashing
// megabytes of pixels per frame.
std::string file_stamp(const std::string& path);

}  // namespace tempera

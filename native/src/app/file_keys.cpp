#include "tempera/app/file_keys.hpp"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "tempera/engine/error.hpp"

namespace fs = std::filesystem;

namespace tempera {

std::string frame_file(const std::string& prefix, int frame, const std::string& extension) {
  char number[32];
  std::snprintf(number, sizeof number, "%04d", frame);
  return prefix + number + "." + extension;
}

std::string hash_hex(const std::string& text) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  std::ostringstream out;
  out << std::hex << std::setw(16) << std::setfill('0') << h;
  return out.str();
}

std::string file_stamp(const std::string& path) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  const auto mtime = fs::last_write_time(path, ec).time_since_epoch().count();
  return concat(size, "|", mtime);
}

}  // namespace tempera

#include "tempera/app/paths.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "tempera/engine/error.hpp"

namespace fs = std::filesystem;

namespace tempera {

bool same_path(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) {
    const bool same = fs::equivalent(a, b, ec);
    if (!ec) return same;
  }
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return ca.lexically_normal() == cb.lexically_normal();
}

void remove_stale_temporaries(const std::string& folder) {
  std::error_code ec;
  const auto now = fs::file_time_type::clock::now();
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() < 2 || name[0] != '.' || name.find(".tmp") == std::string::npos) continue;
    std::error_code stat_ec;
    const auto written = fs::last_write_time(it->path(), stat_ec);
    if (!stat_ec && now - written > std::chrono::hours(1) && fs::is_regular_file(it->path(), stat_ec))
      fs::remove(it->path(), stat_ec);
  }
}

void create_output_folder(const std::string& folder) {
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (!fs::is_directory(folder, ec))
    throw IoError(concat("cannot create the output folder '", folder, "'", ec ? ": " + ec.message() : ""));
}

void refuse_output_on_inputs(const std::string& output, const std::vector<std::string>& inputs,
                             const std::string& what) {
  for (const auto& spec : inputs) {
    std::vector<std::string> candidates = {spec};
    const std::size_t colon = spec.rfind(':');
    if (colon != std::string::npos && colon > 0) candidates.push_back(spec.substr(0, colon));
    for (const auto& input : candidates)
      if (!input.empty() && same_path(output, input))
        throw ValueError(concat(what, " '", output, "' is also an input ('", spec,
                                "'): writing it would destroy the input; choose another output"));
  }
}

namespace {
// A folder is locked through itself (no lock file left behind), a file is created if missing.
int open_for_lock(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  return ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
}
}  // namespace

FileLock::FileLock(const std::string& path) {
  fd_ = open_for_lock(path);
  if (fd_ < 0) throw IoError(concat("cannot open the lock file '", path, "': ", std::strerror(errno)));
  while (::flock(fd_, LOCK_EX) != 0) {
    if (errno == EINTR) continue;
    const int error = errno;
    ::close(fd_);
    fd_ = -1;
    throw IoError(concat("cannot lock '", path, "': ", std::strerror(error)));
  }
}

std::unique_ptr<FileLock> FileLock::try_lock(const std::string& path) {
  const int fd = open_for_lock(path);
  if (fd < 0) throw IoError(concat("cannot open the lock file '", path, "': ", std::strerror(errno)));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    return nullptr;
  }
  std::unique_ptr<FileLock> lock(new FileLock());
  lock->fd_ = fd;
  return lock;
}

FileLock::~FileLock() {
  if (fd_ >= 0) ::close(fd_);  // closing releases the lock
}

FileDigest file_digest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  FileDigest d;
  if (!in) return d;
  std::uint64_t h = 1469598103934665603ull;
  std::int64_t size = 0;
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    const std::streamsize n = in.gcount();
    for (std::streamsize i = 0; i < n; ++i) h = (h ^ static_cast<unsigned char>(buffer[i])) * 1099511628211ull;
    size += n;
  }
  if (in.bad()) return d;
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  d.size = size;
  d.checksum = text;
  return d;
}

}  // namespace tempera

#include "tempera/app/scratch_images.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "tempera/engine/error.hpp"

namespace tempera {
namespace {

std::size_t page_size() {
  static const std::size_t size = std::size_t(sysconf(_SC_PAGESIZE));
  return size;
}

}  // namespace

ScratchImages::ScratchImages(const std::string& folder) : folder_(folder) {
  fd_ = ::open(folder.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  // EISDIR / EOPNOTSUPP: the file system cannot make unnamed files; plain
  // memory then. Anything else (no folder, no permission) is the caller's
  // folder being wrong, which the job's own writes would meet too.
  if (fd_ < 0 && errno != EISDIR && errno != EOPNOTSUPP)
    throw IoError(concat("cannot make a scratch file in '", folder, "': ", std::strerror(errno)));
}

ScratchImages::~ScratchImages() {
  for (const Mapping& m : mappings_) ::munmap(m.address, m.length);
  if (fd_ >= 0) ::close(fd_);  // the file had no name: closing it frees its space
}

ImageView ScratchImages::add(const ImageView& image) {
  const std::size_t bytes = image.size() * sizeof(float);
  if (bytes == 0) return image;  // nothing to keep
  if (!disk_backed()) {
    const Image& kept = in_memory_.emplace_back(Image::copy_of(image));
    return kept.view();
  }
  const std::size_t length = (bytes + page_size() - 1) / page_size() * page_size();
  // Reserved now: a mapped page that cannot be written back later is a SIGBUS.
  if (const int e = ::posix_fallocate(fd_, off_t(bytes_), off_t(length)))
    throw IoError(concat("cannot write the shot's inputs to a scratch file in '", folder_, "' (", (length + 0xFFFFF) >> 20,
                         " MB more): ", std::strerror(e), " (is the disk full?)"));
  void* address = ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, off_t(bytes_));
  if (address == MAP_FAILED) throw IoError(concat("cannot map the scratch file in '", folder_, "': ", std::strerror(errno)));
  mappings_.push_back({address, length});
  std::memcpy(address, image.data, bytes);
  // Written back from now on, so that the pages are clean (free to drop at
  // once) by the time memory runs short.
  ::sync_file_range(fd_, off_t(bytes_), off_t(length), SYNC_FILE_RANGE_WRITE);
  bytes_ += length;
  return ImageView{static_cast<const float*>(address), image.width, image.height, image.channels};
}

}  // namespace tempera

#pragma once
// Images that a job holds for a long time but reads only now and then (the
// coherent method's guides and motion of every frame of a segment, read at
// each visit of the frame), kept where the kernel can give their memory back.
//
// Anonymous memory (an Image) can only be given back by swapping, and farm
// machines often have no swap: a segment whose inputs and state pass the
// machine's memory is killed. These images live in an unnamed file on disk
// (O_TMPFILE in the folder given: it has no name, so nothing is ever left
// behind, whatever ends the process) mapped into memory. While memory is
// free they stay resident and are read as fast as an Image; under pressure
// the kernel writes them back and drops them, and reads them again when a
// visit needs them. Their space on disk is reserved as each is added, so a
// full disk is an IoError naming the folder, never a SIGBUS later.
//
// A folder whose file system has no O_TMPFILE gets plain memory instead
// (disk_backed() false): the job then runs exactly as it did without this.
#include <cstddef>
#include <string>
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

class ScratchImages {
 public:
  explicit ScratchImages(const std::string& folder);
  ~ScratchImages();
  ScratchImages(const ScratchImages&) = delete;
  ScratchImages& operator=(const ScratchImages&) = delete;

  // A copy of `image` (the same floats) that stays valid while this lives.
  ImageView add(const ImageView& image);
  ImageView add(const Image& image) { return add(image.view()); }

  bool disk_backed() const { return fd_ >= 0; }
  std::size_t bytes() const { return bytes_; }  // of the images added, rounded up to pages

 private:
  std::string folder_;
  int fd_ = -1;
  std::size_t bytes_ = 0;
  struct Mapping {
    void* address;
    std::size_t length;
  };
  std::vector<Mapping> mappings_;
  std::vector<Image> in_memory_;  // without O_TMPFILE
};

}  // namespace tempera

#pragma once
// File-system guards shared by the CLI, the stylize job and the bindings:
// refusing outputs that would overwrite inputs, advisory locks for folders
// that several processes (a render farm) write into, and file checksums for
// the integrity records of resumable outputs.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace tempera {

// True if `a` and `b` name the same file or folder (after resolving "..",
// symbolic links and, for existing paths, hard links).
bool same_path(const std::string& a, const std::string& b);

// ValueError if `output` is one of `inputs` (each an image path, or
// "FILE:LAYER" whose FILE counts): `what` names the output option, e.g.
// "--output". Overwriting an input would destroy it before it is read again.
void refuse_output_on_inputs(const std::string& output, const std::vector<std::string>& inputs,
                             const std::string& what);

// Creates `folder` and its parents, at a job's first write rather than when
// it is set up, so that a refused job leaves nothing behind. IoError naming
// `folder` if it cannot be made.
void create_output_folder(const std::string& folder);

// Removes the temporary files (".<name>.tmp<pid>-<random>...") of writers
// killed with -9 from `folder`. A live writer holds one for the seconds an
// image takes to write, so one older than an hour is dead; it is never read.
void remove_stale_temporaries(const std::string& folder);

// An exclusive advisory lock (flock) on `path`, held until destruction: a
// folder is locked through itself, a file is created if missing. Blocks while another process holds it. IoError naming
// the file if it cannot be opened.
class FileLock {
 public:
  explicit FileLock(const std::string& path);
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

  // The lock if it is free, else nullptr (another process holds it).
  static std::unique_ptr<FileLock> try_lock(const std::string& path);

 private:
  FileLock() = default;
  int fd_ = -1;
};

// Size in bytes and 64-bit FNV-1a hash (16 hex digits) of a file's bytes;
// size -1 and "" if it cannot be read.
struct FileDigest {
  std::int64_t size = -1;
  std::string checksum;
  bool operator==(const FileDigest& o) const { return size == o.size && checksum == o.checksum; }
};
FileDigest file_digest(const std::string& path);

// The largest frame number Blender can render (MAXFRAME in Blender's DNA);
// frame ranges are bounded by it so that no range is unbounded.
constexpr int kMaxFrame = 1048574;

}  // namespace tempera

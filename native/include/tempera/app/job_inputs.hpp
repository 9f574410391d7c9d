#pragma once
// What a job reads, file by file and folder by folder, named for messages.
// The job core holds every job to one rule with it: a job writes, replaces or
// deletes only files that it creates in its output folder, never one of its
// inputs (guide frames, exemplars, paintings, keys, masks, reference frames).
//
// Files are told apart by what they are on disk (device and inode), so a
// symbolic link, "..", or a hard link to an input is refused like the input.
#include <cstdint>
#include <string>
#include <vector>

namespace tempera {

class JobInputs {
 public:
  // `what` names the input in messages: "painting", "guide frame".
  void add_file(const std::string& path, const std::string& what);
  // A folder the job lists or reads from; `contents` says what writing into
  // it would harm: "the guides", "the exemplar's frames".
  void add_folder(const std::string& path, const std::string& what, const std::string& contents);

  // ValueError if the output folder `out` is one of the input folders.
  void refuse_folder(const std::string& out) const;
  // ValueError if writing `output` would replace one of the input files.
  void refuse_file(const std::string& output) const;

 private:
  struct Input {
    std::uint64_t device = 0, inode = 0;
    std::string path, what, contents;
  };
  static bool identify(const std::string& path, Input& input);
  static const Input* find(const std::vector<Input>& inputs, const std::string& path);
  std::vector<Input> files_, folders_;
};

}  // namespace tempera

#include "tempera/app/job_inputs.hpp"

#include <sys/stat.h>

#include <algorithm>

#include "tempera/engine/error.hpp"

namespace tempera {

// Device and inode of what `path` names, following symbolic links; false if
// nothing is there (a missing output cannot be an existing input).
bool JobInputs::identify(const std::string& path, Input& input) {
  struct stat s {};
  if (path.empty() || ::stat(path.c_str(), &s) != 0) return false;
  input.device = std::uint64_t(s.st_dev), input.inode = std::uint64_t(s.st_ino);
  return true;
}

void JobInputs::add_file(const std::string& path, const std::string& what) {
  Input in{0, 0, path, what, ""};
  if (identify(path, in)) files_.push_back(std::move(in));
}

void JobInputs::add_folder(const std::string& path, const std::string& what, const std::string& contents) {
  Input in{0, 0, path, what, contents};
  if (identify(path, in)) folders_.push_back(std::move(in));
}

// The input among `inputs` that `path` is on disk, or nullptr.
const JobInputs::Input* JobInputs::find(const std::vector<Input>& inputs, const std::string& path) {
  Input o;
  if (!identify(path, o)) return nullptr;
  for (const Input& in : inputs)
    if (in.device == o.device && in.inode == o.inode) return &in;
  return nullptr;
}

void JobInputs::refuse_folder(const std::string& out) const {
  if (const Input* in = find(folders_, out))
    throw ValueError(concat("the output folder '", out, "' is the ", in->what, " folder ('", in->path,
                            "'): the outputs would overwrite ", in->contents, "; choose another output folder"));
}

void JobInputs::refuse_file(const std::string& output) const {
  if (const Input* in = find(files_, output))
    throw ValueError(concat("'", output, "' would overwrite the ", in->what, " '", in->path,
                            "', an input; choose another output folder"));
}

}  // namespace tempera

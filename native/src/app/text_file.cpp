#include "tempera/app/text_file.hpp"
#include <filesystem>
#include <fstream>
#include "tempera/engine/error.hpp"
#include "tempera/app/image_io.hpp"

namespace fs = std::filesystem;

namespace tempera {

void write_text_atomically(const std::string& path, const std::string& text, const std::string& what) {
  const fs::path target(path);
  const fs::path temp = target.parent_path() / temporary_name(target.filename().string(), "");
  std::error_code ec;
  {
    std::ofstream out(temp);
    out << text;
    out.close();
    // A full disk may only show as a short file: the size is checked too.
    if (!out || fs::file_size(temp, ec) != text.size() || ec) {
      fs::remove(temp, ec);
      throw IoError(concat("cannot write ", what, " '", path, "'"));
    }
  }
  fs::rename(temp, target, ec);
  if (ec) {
    const std::string why = ec.message();  // before remove() resets ec ("...: Success")
    fs::remove(temp, ec);
    throw IoError(concat("cannot move ", what, " into place at '", path, "': ", why));
  }
}

}  // namespace tempera

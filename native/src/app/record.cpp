#include "tempera/app/record.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tempera/app/paths.hpp"
#include "tempera/app/text_file.hpp"

namespace fs = std::filesystem;

namespace tempera {

void write_record(const std::string& record, const std::string& format, const std::string& key,
                  const std::vector<std::string>& files) {
  std::ostringstream text;
  text << format << "\n" << key << "\n";
  for (const std::string& path : files) {
    const FileDigest d = file_digest(path);
    text << fs::path(path).filename().string() << " " << d.size << " " << d.checksum << "\n";
  }
  write_text_atomically(record, text.str(), "the resume record");
}

bool record_current(const std::string& record, const std::string& format, const std::string& key,
                    const std::vector<std::string>& files) {
  std::ifstream in(record);
  std::string line;
  if (!in || !std::getline(in, line) || line != format) return false;
  if (!std::getline(in, line) || line != key) return false;
  for (const std::string& path : files) {
    std::string name;
    FileDigest recorded;
    if (!(in >> name >> recorded.size >> recorded.checksum)) return false;
    if (name != fs::path(path).filename().string() || !(file_digest(path) == recorded)) return false;
  }
  return true;
}

}  // namespace tempera

#include "tempera/app/frame_report.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>

#include "tempera/app/image_io.hpp"  // temporary_name
#include "tempera/app/text_file.hpp"
#include "tempera/engine/error.hpp"

namespace fs = std::filesystem;

namespace tempera {
namespace {

std::string json_string(const std::string& text) {
  std::ostringstream out;
  out << '"';
  for (unsigned char c : text) {
    if (c == '"' || c == '\\') out << '\\' << c;
    else if (c < 0x20) out << "\\u" << std::hex << std::setw(4) << std::setfill('0') << int(c) << std::dec;
    else out << c;
  }
  out << '"';
  return out.str();
}

std::string json_number(double value) {
  if (!std::isfinite(value)) return "null";
  std::ostringstream out;
  out << std::setprecision(9) << value;
  return out.str();
}

// Reads one report line as write_report() writes it, left to right:
//   "12": {"key": "...", "file": "...", "flicker": 0.01, "source_coverage": 0.9},
class LineReader {
 public:
  explicit LineReader(const std::string& line) : line_(line) {}
  void expect(const std::string& text) {
    skip_spaces();
    if (line_.compare(pos_, text.size(), text) != 0) throw ValueError("unexpected report text");
    pos_ += text.size();
  }
  std::string string() {
    expect("\"");
    std::string out;
    while (pos_ < line_.size() && line_[pos_] != '"') {
      char c = line_[pos_++];
      if (c == '\\' && pos_ < line_.size()) {
        c = line_[pos_++];
        if (c == 'u') {  // only control characters are written this way
          c = char(std::stoi(line_.substr(pos_, 4), nullptr, 16));
          pos_ += 4;
        }
      }
      out += c;
    }
    expect("\"");
    return out;
  }
  double number() {
    skip_spaces();
    if (line_.compare(pos_, 4, "null") == 0) {
      pos_ += 4;
      return std::numeric_limits<double>::quiet_NaN();
    }
    std::size_t used = 0;
    const double value = std::stod(line_.substr(pos_), &used);
    pos_ += used;
    return value;
  }

 private:
  void skip_spaces() {
    while (pos_ < line_.size() && line_[pos_] == ' ') ++pos_;
  }
  const std::string& line_;
  std::size_t pos_ = 0;
};

// Reads exactly the format write_report() writes: one frame per line. A file
// that is not such a report (damaged, or from another Tempera version) is
// renamed aside with a warning and counts as "no frames done": its frames
// are redone, never wrongly skipped, and nothing of it is lost.
std::map<int, ReportedFrame> read_report(const std::string& path, const std::string& format,
                                        std::vector<std::string>& warnings) {
  std::map<int, ReportedFrame> entries;
  std::error_code ec;
  if (!fs::exists(path, ec)) return entries;
  std::ifstream in(path);
  std::string line;
  bool ok = in && std::getline(in, line) && line == "{" && std::getline(in, line) &&
            line == concat("  \"format\": ", json_string(format), ",");
  bool closed = false;  // the final "}": a truncated record is damaged, not short
  try {
    while (ok && std::getline(in, line)) {
      if (closed) ok = false;  // text after the end
      if (line == "}") closed = true;
      if (line.find("{\"key\": ") == std::string::npos) {
        if (line.find("\"key\"") != std::string::npos) ok = false;
        continue;
      }
      LineReader r(line);
      const std::string number = r.string();
      int frame = -1;
      const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), frame);
      if (error != std::errc() || end != number.data() + number.size() || frame < 0 || frame > kMaxFrame)
        throw ValueError("bad frame number");
      ReportedFrame e;
      r.expect(": {\"key\":");
      e.key = r.string();
      r.expect(", \"file\":");
      e.file = r.string();
      r.expect(", \"flicker\":");
      e.flicker = r.number();
      r.expect(", \"source_coverage\":");
      e.source_coverage = r.number();
      r.expect(", \"size\":");
      e.digest.size = std::int64_t(r.number());
      r.expect(", \"checksum\":");
      e.digest.checksum = r.string();
      r.expect("}");
      entries[frame] = e;
    }
  } catch (const std::exception&) {
    ok = false;
  }
  if (ok && closed) return entries;
  const std::string aside = concat(path, ".corrupt-", temporary_name("", "").substr(5));
  fs::rename(path, aside, ec);
  warnings.push_back(concat("the resume record '", path, "' is damaged or from another Tempera version; ",
                            ec ? "it is ignored" : concat("set aside as '", aside, "'"),
                            " and its frames are stylized again"));
  return {};
}


void write_report(const std::string& path, const std::string& format, const std::string& settings,
                  const std::map<int, ReportedFrame>& entries) {
  std::ostringstream out;
  out << "{\n  \"format\": " << json_string(format) << ",\n  \"settings\": " << json_string(settings)
      << ",\n  \"frames\": {";
  std::size_t i = 0;
  for (const auto& [frame, e] : entries)
    out << (i++ ? ",\n" : "\n") << "    \"" << frame << "\": {\"key\": " << json_string(e.key)
        << ", \"file\": " << json_string(e.file) << ", \"flicker\": " << json_number(e.flicker)
        << ", \"source_coverage\": " << json_number(e.source_coverage) << ", \"size\": " << e.digest.size
        << ", \"checksum\": " << json_string(e.digest.checksum) << "}";
  out << "\n  }\n}\n";
  write_text_atomically(path, out.str(), "the job report");
}

}  // namespace

FrameReport::FrameReport(std::string folder, const std::string& name, std::string format)
    : folder_(std::move(folder)), path_((fs::path(folder_) / name).string()), format_(std::move(format)) {}

std::optional<ReportedFrame> FrameReport::current(int frame, const std::string& key, const std::string& output,
                                                  std::vector<std::string>& warnings) const {
  std::map<int, ReportedFrame> done;
  {
    FileLock lock(folder_);
    done = read_report(path_, format_, warnings);
  }
  const auto it = done.find(frame);
  std::error_code ec;
  if (it == done.end() || it->second.key != key || !fs::is_regular_file(output, ec) ||
      !(file_digest(output) == it->second.digest))
    return std::nullopt;
  return it->second;
}

void FrameReport::add(int frame, const ReportedFrame& entry, const std::string& settings,
                      std::vector<std::string>& warnings) const {
  FileLock lock(folder_);
  auto entries = read_report(path_, format_, warnings);
  entries[frame] = entry;
  write_report(path_, format_, settings, entries);
}

}  // namespace tempera

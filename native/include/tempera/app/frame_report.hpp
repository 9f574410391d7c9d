#pragma once
// The shared frame report: the resume record of a job whose frames several
// processes write into one output folder (farm tasks splitting a shot
// anywhere, each adding its own frames). One JSON file in the folder,
// readable by people and pipelines, one line per frame: the frame's key
// (settings and inputs), its file, its FrameResult measures (flicker, source
// coverage) and the file's size and checksum. Every read-merge-write happens
// under the folder's lock (FileLock on the folder itself: no lock file), and
// the file is replaced atomically.
//
// A report that is damaged or of another format is set aside (renamed
// NAME.corrupt-...) with a warning and counts as "no frames done": frames are
// redone, never wrongly skipped. (The per-unit record of app/record.hpp is the
// other record of the core: one small file per frame or segment, which needs
// no lock.)
#include <optional>
#include <string>
#include <vector>

#include "tempera/app/paths.hpp"  // FileDigest

namespace tempera {

struct ReportedFrame {
  std::string key, file;
  double flicker = 0, source_coverage = 0;
  FileDigest digest;  // of the output file as written: a changed or damaged file is redone
};

class FrameReport {
 public:
  // The report `name` (e.g. "tempera_stylize.json") of the folder `folder`, in `format`.
  FrameReport(std::string folder, const std::string& name, std::string format);
  const std::string& path() const { return path_; }

  // The frame's entry when it is current: the same key, and `output` is the
  // file that was written (size and checksum). Warnings say what was set aside.
  std::optional<ReportedFrame> current(int frame, const std::string& key, const std::string& output,
                                       std::vector<std::string>& warnings) const;

  // Adds (or replaces) the frame's entry, merged with what other processes
  // wrote meanwhile; `settings` is the job's settings text, for people.
  void add(int frame, const ReportedFrame& entry, const std::string& settings,
           std::vector<std::string>& warnings) const;

 private:
  std::string folder_, path_, format_;
};

}  // namespace tempera

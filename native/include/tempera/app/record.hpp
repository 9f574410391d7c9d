#pragma once
// The resume record of a job's unit of work (a frame, a segment): the key of
// everything the unit was made from and a digest of every file it wrote.
//
//   <format line>                  the job's record format, e.g. "tempera-<method>-frame 2"
//   <key>                          hash of the settings and inputs
//   <file name> <size> <checksum>  one line per file written, in order
//
// The record is written last and atomically, so a crash leaves either no
// record or a matching one. A unit is current when its record has the same
// format and key and every file is still the one written: a deleted,
// truncated or overwritten output is made again.
#include <string>
#include <vector>

namespace tempera {

// IoError naming the record if it cannot be written.
void write_record(const std::string& record, const std::string& format, const std::string& key,
                  const std::vector<std::string>& files);

// False for a missing, damaged or older record, another key, or a file that changed.
bool record_current(const std::string& record, const std::string& format, const std::string& key,
                    const std::vector<std::string>& files);

}  // namespace tempera

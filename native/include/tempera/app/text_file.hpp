// Small text files that must never be seen half-written: resume records,
// job reports, stats.
#pragma once
#include <string>

namespace tempera {

// Writes `text` to a temporary file beside `path`, checks its size (a full
// disk may only show as a short file), then renames it into place, so a
// crash, cancel or full disk leaves either the old file or the new one. IoError
// names `what` (e.g. "the job report") and `path`; the temporary is removed.
void write_text_atomically(const std::string& path, const std::string& text, const std::string& what);

}  // namespace tempera

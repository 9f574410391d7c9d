#include "frame_loop.hpp"

#include <malloc.h>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "tempera/engine/error.hpp"

namespace tempera::cli {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;
void on_signal(int) { g_interrupted = 1; }

// A frame's large images (stacked guides, pyramids, features: tens of MB at
// 1 Mpix) are allocated and freed at every frame and level. glibc gives
// blocks past its mmap threshold (which adapts up to 32 MB) fresh mappings,
// which the kernel faults in and zeroes page by page at every use: a tenth of
// the coherent method's CPU at 1 Mpix, more at larger frames. A run over
// frames keeps them in its heap for reuse (docs/benchmarks.md, issue 32 step
// 25). Not `tempera synth`: one still reuses little and would peak 15 MB
// higher; nor the Python module, which leaves its host's allocator alone.
void keep_large_blocks_for_reuse() {
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

}  // namespace

void catch_interrupts() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool interrupted() { return g_interrupted != 0; }

const volatile std::sig_atomic_t* interrupt_flag() { return &g_interrupted; }

ProgressCallback until_interrupted() {
  return [](double) { return !interrupted(); };
}

int report_interrupted(const std::string& command, const std::string& unit) {
  std::cerr << "tempera " << command << ": interrupted; finished " << unit
            << "s are kept, rerun the same command to resume\n";
  return kInterruptedStatus;
}

std::string clock_text(double seconds) {
  const long s = std::lround(seconds);
  std::ostringstream out;
  out << s / 60 << ":" << std::setw(2) << std::setfill('0') << s % 60;
  return out.str();
}

bool run_units(const std::vector<std::size_t>& units, std::size_t total,
               const std::function<FrameResult(std::size_t, const ProgressCallback&)>& run,
               std::vector<FrameResult>& results, const FrameLine& line) {
  keep_large_blocks_for_reuse();
  double spent = 0;
  int made = 0;
  for (std::size_t k = 0; k < units.size(); ++k) {
    const std::size_t i = units[k];
    if (interrupted()) return false;
    try {
      results.push_back(run(i, until_interrupted()));
    } catch (const CancelledError&) {
      return false;
    }
    const FrameResult& r = results.back();
    std::cout << line.label << " " << i + 1 << "/" << total << " ("
              << (line.which ? line.which(i, r) : concat("#", r.frame)) << "): ";
    if (r.status == "skipped") {
      std::cout << "skipped, already current";
    } else {
      spent += r.seconds;
      ++made;
      std::cout << std::fixed << std::setprecision(2) << r.seconds << " s" << std::defaultfloat;
    }
    if (line.details) line.details(std::cout, r);
    const std::size_t left = units.size() - k - 1;
    if (line.eta && made > 0 && left > 0) std::cout << ", ETA " << clock_text(spent / made * double(left));
    std::cout << std::defaultfloat << std::endl;
  }
  return true;
}

bool run_frames(FrameJob& job, std::vector<FrameResult>& results, const FrameLine& line) {
  std::vector<std::size_t> all(job.frames().size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  return run_units(all, all.size(), [&](std::size_t i, const ProgressCallback& cancel) { return job.run_frame(i, cancel); },
                   results, line);
}

bool write_beside_frames(const std::string& command, const std::string& what, const std::function<void()>& write) {
  try {
    write();
    return true;
  } catch (const IoError& e) {
    std::cerr << "tempera " << command << ": warning: " << what << " was not written (" << e.what()
              << "); the frames are done\n";
    return false;
  }
}

FrameTally tally(const std::vector<FrameResult>& results) {
  FrameTally t;
  for (const auto& r : results) {
    if (r.status == "skipped") {
      ++t.skipped;
    } else {
      ++t.made;
      t.seconds += r.seconds;
    }
  }
  return t;
}

}  // namespace tempera::cli

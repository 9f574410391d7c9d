#include "frame_loop.hpp"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "tempera/engine/error.hpp"

namespace tempera::cli {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;
void on_signal(int) { g_interrupted = 1; }

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

bool run_frames(FrameJob& job, std::vector<FrameResult>& results, const FrameLine& line) {
  const std::size_t n = job.frames().size();
  double spent = 0;
  int made = 0;
  for (std::size_t i = 0; i < n; ++i) {
    try {
      results.push_back(job.run_frame(i, until_interrupted()));
    } catch (const CancelledError&) {
      return false;
    }
    const FrameResult& r = results.back();
    std::cout << line.label << " " << i + 1 << "/" << n << " (#" << r.frame << "): ";
    if (r.status == "skipped") {
      std::cout << "skipped, already current";
    } else {
      spent += r.seconds;
      ++made;
      std::cout << std::fixed << std::setprecision(2) << r.seconds << " s" << std::defaultfloat;
    }
    if (line.details) line.details(std::cout, r);
    if (line.eta && made > 0 && i + 1 < n) std::cout << ", ETA " << clock_text(spent / made * double(n - i - 1));
    std::cout << std::defaultfloat << std::endl;
  }
  return true;
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

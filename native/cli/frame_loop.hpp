#pragma once
// The command line's one interrupt path and one frame loop.
//
// SIGINT and SIGTERM (Ctrl-C; a farm's or the panel's cancel) only set a
// flag. A job polls it through its progress callback and stops before it
// writes anything of the frame (CancelledError); a child process the command
// waits on (Blender) is stopped by run_process when it sees the flag. The
// command then exits 130, and the same command again resumes from the frames
// kept.
#include <csignal>
#include <cstddef>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "tempera/app/frame_job.hpp"

namespace tempera::cli {

constexpr int kInterruptedStatus = 130;

// Installs the handler of SIGINT and SIGTERM.
void catch_interrupts();
bool interrupted();
// The flag the handler sets, for run_process and render_guides_in_blender.
const volatile std::sig_atomic_t* interrupt_flag();
// A job's progress callback: false (cancel) once interrupted.
ProgressCallback until_interrupted();

// "tempera COMMAND: interrupted; finished UNITs are kept, rerun the same
// command to resume" on stderr; returns kInterruptedStatus.
int report_interrupted(const std::string& command, const std::string& unit = "frame");

// "1:05" for 65 seconds.
std::string clock_text(double seconds);

// How the loop prints a job's units of work.
struct FrameLine {
  std::string label = "frame";  // the line's start: "frame 3/24 (#3): "
  // Which unit, in the brackets: "#3" by default (the result's frame); a segment says "frames 1-8".
  std::function<std::string(std::size_t unit, const FrameResult&)> which;
  // Figures of the method after the time (", flicker 0.0123"), for made and skipped frames alike.
  std::function<void(std::ostream&, const FrameResult&)> details;
  bool eta = false;  // ", ETA 1:05" once a frame was made
};

// The one loop over a job's units of work (frames, or a segment job's segments): runs
// `run(unit)` for each of `units` in order, with until_interrupted() as its
// cancel, one line each, "frame 3/24 (#3): 1.23 s" or "frame 3/24 (#3):
// skipped, already current" (24 = `total`), and appends its result to
// `results`. False if interrupted (the units finished before are kept).
bool run_units(const std::vector<std::size_t>& units, std::size_t total,
               const std::function<FrameResult(std::size_t unit, const ProgressCallback&)>& run,
               std::vector<FrameResult>& results, const FrameLine& line = {});

// run_units over every frame of `job`.
bool run_frames(FrameJob& job, std::vector<FrameResult>& results, const FrameLine& line = {});

// Writes what a command makes beside its frames (the contact sheet, the
// video). The frames are the product: a file that cannot be written there
// (a read-only or full folder) is a warning on stderr, not a failed job.
// True if `write` finished.
bool write_beside_frames(const std::string& command, const std::string& what, const std::function<void()>& write);

// Seconds spent on frames made, and how many were made and skipped.
struct FrameTally {
  int made = 0, skipped = 0;
  double seconds = 0;
};
FrameTally tally(const std::vector<FrameResult>& results);

}  // namespace tempera::cli

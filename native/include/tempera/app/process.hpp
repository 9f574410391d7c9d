#pragma once
// Child processes without a shell (argument lists, never command strings):
// Blender for guide renders, ffmpeg for videos.
#include <csignal>
#include <string>
#include <vector>

namespace tempera {

// Encodes frames `pattern` (printf style, e.g. "out/frame_%04d.png") from
// `first_frame` on into an H.264 MP4 (yuv420p, dimensions rounded down to
// even) with ffmpeg, atomically. Returns false, writing nothing, when ffmpeg
// is not on PATH; IoError when ffmpeg fails.
// `text` with every '%' doubled, for a literal part of a printf-style pattern
// (ffmpeg reads "frames%d/frame_%04d.png" as two numbers).
std::string printf_escaped(const std::string& text);

bool encode_video(const std::string& pattern, int first_frame, double fps, const std::string& out_path);

// Runs argv (no shell; argv[0] looked up on PATH), waits, returns the exit
// status (128 + signal if killed, 127 if it could not be started). With
// `quiet`, stdin is /dev/null and stdout is discarded.
// `interrupted`: a flag set by the caller's SIGINT handler; once set, the
// child gets SIGTERM (it got the terminal's SIGINT too, which it may ignore).
int run_process(const std::vector<std::string>& argv, bool quiet = false,
                const volatile std::sig_atomic_t* interrupted = nullptr);

// Full path of `program` found on PATH, or "" when absent.
std::string find_on_path(const std::string& program);

}  // namespace tempera

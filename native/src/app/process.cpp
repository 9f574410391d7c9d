#include "tempera/app/process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "tempera/engine/error.hpp"
#include "tempera/app/image_io.hpp"

namespace fs = std::filesystem;

namespace tempera {

std::string find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const fs::path candidate = fs::path(dirs.substr(start, end - start)) / program;
    if (end > start && access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate)) return candidate;
    start = end + 1;
  }
  return "";
}

int run_process(const std::vector<std::string>& argv, bool quiet, const volatile std::sig_atomic_t* interrupted) {
  std::vector<char*> raw;
  for (const auto& a : argv) raw.push_back(const_cast<char*>(a.c_str()));
  raw.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw IoError(concat("cannot start '", argv[0], "': fork failed"));
  if (pid == 0) {
    // The child (Blender, ffmpeg) must not outlive this process, even killed
    // with SIGKILL: it would go on writing into the output. If the parent
    // died before the request took effect, stop at once.
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    if (quiet) {  // keep a child (ffmpeg) from reading the terminal or flooding stdout
      const int null = open("/dev/null", O_RDWR);
      dup2(null, STDIN_FILENO);
      dup2(null, STDOUT_FILENO);
    }
    execvp(raw[0], raw.data());
    _exit(127);
  }
  int status = 0;
  bool terminated = false;
  while (waitpid(pid, &status, 0) < 0) {
    // Interrupted by a signal (EINTR): after Ctrl-C, make sure the child
    // stops too (Blender ignores a Ctrl-C that comes between two renders).
    if (interrupted && *interrupted && !terminated) {
      kill(pid, SIGTERM);
      terminated = true;
    }
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string printf_escaped(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out;
}

bool encode_video(const std::string& pattern, int first_frame, double fps, const std::string& out_path) {
  if (!(fps > 0) || !std::isfinite(fps)) throw ValueError(concat("fps must be a positive number, got ", fps));
  const std::string ffmpeg = find_on_path("ffmpeg");
  if (ffmpeg.empty()) return false;
  const fs::path target(out_path);
  // Same folder, so the final rename is atomic; .mp4 so ffmpeg picks the muxer.
  // Both paths absolute: ffmpeg reads a relative '-y' or '-dash/...' as an option
  // and 'shot:01/...' or 'http:h/...' as a URL; from '/' on it is a file.
  const fs::path temp = fs::absolute(target.parent_path() / temporary_name(target.stem().string(), ".mp4"));
  const std::string input = fs::path(pattern).is_absolute()
                                ? pattern
                                : printf_escaped(fs::current_path().string()) + "/" + pattern;
  const std::vector<std::string> argv = {
      ffmpeg, "-y", "-nostdin", "-loglevel", "error", "-framerate", concat(fps), "-start_number",
      std::to_string(first_frame), "-i", input,
      // libx264 with yuv420p needs even sizes: drop at most one row / column.
      "-vf", "scale=trunc(iw/2)*2:trunc(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p", temp.string()};
  const int status = run_process(argv, true);
  std::error_code ec;
  if (status != 0 || !fs::is_regular_file(temp, ec)) {
    fs::remove(temp, ec);
    throw IoError(concat("ffmpeg failed (exit status ", status, ") encoding '", pattern, "' into '", out_path, "'"));
  }
  fs::rename(temp, target, ec);
  if (ec) {
    const std::string why = ec.message();  // before remove() resets ec ("...: Success")
    fs::remove(temp, ec);
    throw IoError(concat("cannot move the video into place at '", out_path, "': ", why));
  }
  return true;
}

}  // namespace tempera

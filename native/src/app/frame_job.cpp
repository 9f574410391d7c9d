#include "tempera/app/frame_job.hpp"

#include "tempera/engine/error.hpp"

#include <stdexcept>

namespace tempera {

const std::vector<std::string>& FrameJob::warnings() const {
  static const std::vector<std::string> none;
  return none;
}

void FrameJob::write_contact_sheet(const std::string&, int) const {
  throw std::logic_error("this method has no contact sheet (has_contact_sheet() is false)");
}

FrameResult ChainedFrameJob::run_frame(std::size_t index, const ProgressCallback& progress) {
  const std::size_t count = frames().size();
  if (index >= count)
    throw ValueError(concat("frame index ", index, " is out of range (the job has ", count, " frames)"));
  made_.resize(count, false);
  if (is_current(index)) {
    FrameResult skipped;
    skipped.frame = frames()[index];
    skipped.path = output_path(skipped.frame);
    skipped.status = "skipped";
    return skipped;
  }
  std::size_t first = index;
  while (first > 0 && !made_[first - 1] && !is_current(first - 1)) --first;
  FrameResult result;
  // A loop, not recursion: a shot of 40,000 frames must not grow the stack.
  for (std::size_t j = first; j <= index; ++j) {
    const double done = double(j - first), total = double(index - first + 1);
    const ProgressCallback part = [&](double f) { return !progress || progress((done + f) / total); };
    result = make_frame(j, progress ? part : ProgressCallback{});
    made_[j] = true;
  }
  return result;
}

}  // namespace tempera

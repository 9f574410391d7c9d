#include "tempera/app/frame_job.hpp"

namespace tempera {

const std::vector<std::string>& FrameJob::warnings() const {
  static const std::vector<std::string> none;
  return none;
}

}  // namespace tempera

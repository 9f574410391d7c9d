#pragma once
// The M-step: B' from the offset field. Mean voting (Kwatra et al. 2005,
// Wexler et al. 2007) averages the exemplar pixels that the patches covering a
// target pixel bring along; with equal weights it is the least-squares optimum
// of the style energy for a fixed field, so it never raises the energy. The
// other modes (synthesis_options.hpp, OutputMode) copy instead of blending.
#include <cstdint>
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/engine/patchmatch.hpp"
#include "tempera/engine/synthesis_options.hpp"

namespace tempera {

struct VoteParams {
  OutputMode mode = OutputMode::Mean;
  std::uint64_t seed = 1, stream = 0;  // random voting
  int threads = 0;
  // Targets whose patches vote (default: the active ones). Hard-constrained
  // pixels with a fixed match vote for their neighbours without being voted.
  const std::vector<std::uint8_t>* voters = nullptr;
};

// Returns B' (same channels as `style`) for the active target pixels; inactive
// pixels keep the values of `previous` (or 0 if it is empty).
Image vote(const ImageView& style, const PatchSpace& space, const SearchConstraints& constraints,
           const OffsetField& field, const ImageView& previous, const VoteParams& params);

}  // namespace tempera

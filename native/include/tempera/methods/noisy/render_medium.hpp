#pragma once
// The medium Color Me Noisy boils the render with when the artist gives none
// (`--method noisy` without --exemplar): the shot's first render under a
// paper grain. The paper asks for a medium that looks like R (§3.1); a
// painting or scan of other colours cannot rebuild R's large shapes and the
// synthesis swaps whole regions for the colours it has (measured on the
// demo with the kit's painting). The render's own colours always can, and
// the grain is the texture that boils.
#include <cstdint>

#include "tempera/engine/image.hpp"

namespace tempera {

// `colours` (display sRGB in [0, 1]) times 1 + g, clipped to [0, 1]: g a
// paper grain of white noise smoothed at two scales (a fine tooth of 3 px
// and clumps of 9 px), about 0.11 standard deviation, the same for a seed.
Image render_medium(const ImageView& colours, std::uint64_t seed);

}  // namespace tempera

#pragma once
// EM voting (Kwatra et al. 2005, Wexler et al. 2007): every target pixel
// becomes the average of the exemplar pixels that the patches covering it
// bring along. With equal weights this average is the least-squares optimum of
// the style energy for a fixed NNF, so it never raises the energy.
#include "tempera/image.hpp"
#include "tempera/patchmatch.hpp"

namespace tempera {

// Returns B' (same channels as `style`) for the active target pixels; inactive
// pixels keep the values of `previous` (or 0 if it is empty).
Image vote(const ImageView& style, const PatchSpace& space, const SearchConstraints& constraints,
           const Nnf& nnf, const ImageView& previous, int threads);

}  // namespace tempera

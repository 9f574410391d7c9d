#pragma once
// Layers of Bénard et al. 2013 (§4, Figs. 9 and 10): objects or collections
// painted and synthesized separately, then composited.
//  - Each layer is a shot of its own (tcia.hpp): its painting (or the shared
//    one) over the shared exemplar guides, the frames' guides and the keys.
//  - Its velocities are extrapolated into its background (Fig. 10): every
//    pixel outside the layer's mask moves as the nearest pixel of the layer
//    (the argmin of the mask's distance transform). Texture at the layer's
//    border, and paint beyond it, then moves with the layer instead of with
//    whatever is behind it. χ± are recomputed from the extrapolated fields,
//    so a layer's background is not disoccluded by the other layers. The
//    frame's guides (and its orientation field) are extended the same way:
//    the layer's background looks like the layer's border (as if it were
//    rendered alone), so guides and motion agree there.
//  - The layers' frames are composited back to front, each over the ones
//    behind with its mask as alpha, the back-most layer opaque (it fills
//    what no mask covers). The order is the given one, or per frame by the
//    median depth of each layer's pixels (farthest at the back).
// Choices the paper does not fix: nearest-pixel extrapolation (the paper
// says "using the distance transform of the input layer"), the extended
// guides, the recomputed χ, the median depth and the opaque back-most layer.
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "tempera/methods/tcia/tcia.hpp"

namespace tempera {

struct ShotLayer {
  std::string name;
  std::vector<ImageView> masks;  // per frame of the shot: coverage in [0, 1], 1 channel
  ImageView style;               // the layer's own painting over the shared exemplar guides; empty = Shot::style
  // Optional: the layer's part of the exemplar render (> 0.5); matches come
  // only from there ("constraining the search space to colors of the same
  // layer", §4). Empty: the whole exemplar.
  ImageView style_mask;
};

// `image` (a velocity field, a guide: any channels) where mask > 0.5, and
// elsewhere its value at the nearest such pixel (Fig. 10(d)). A mask with
// no pixel leaves the image as it is.
Image extend_from_mask(const ImageView& image, const ImageView& mask);

// Holds an image layer_shot made for as long as the layer's shot is used;
// returns its view (the coherent job's: a scratch file, app/scratch_images.hpp).
using ImageKeeper = std::function<ImageView(Image&&)>;

// The shot of one layer; its views point into what `keep` holds and `shot`.
// `extrapolate` false keeps the shot's motion (the Fig. 10(c) baseline).
// ValueError naming the layer when its masks or painting do not fit the shot.
Shot layer_shot(const Shot& shot, const ShotLayer& layer, const ImageKeeper& keep, bool extrapolate = true);
// The same, holding the images in `keep`.
Shot layer_shot(const Shot& shot, const ShotLayer& layer, std::deque<Image>& keep, bool extrapolate = true);

// The indices of `masks` from back to front by the median `depth` of each
// mask's pixels (mask > 0.5), farthest first; layers without a pixel go to
// the back, ties and those in their given order.
std::vector<int> depth_order(const ImageView& depth, const std::vector<ImageView>& masks);

// `images` (same size and channels) stacked in `back_to_front` order: the
// first opaque, each next one over it with alpha = its mask (out = a L + (1 - a) out).
Image composite_layers(const std::vector<ImageView>& images, const std::vector<ImageView>& masks,
                       const std::vector<int>& back_to_front);

}  // namespace tempera

#include "tempera/methods/tcia/tcia_layers.hpp"

#include <algorithm>
#include <numeric>

#include "tempera/engine/distance_transform.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/engine/motion.hpp"

namespace tempera {

namespace {

// `image` read at each pixel's nearest layer pixel (nearest_mask_pixel).
Image pick_nearest(const ImageView& image, const Image& nearest) {
  if (nearest.width() != image.width || nearest.height() != image.height)
    throw ValueError(concat("the layer mask is ", nearest.width(), "x", nearest.height(), " but the image it extends is ",
                            image.width, "x", image.height));
  Image out = Image::copy_of(image);
  if (nearest.at(0, 0, 0) < 0) return out;  // an empty mask
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) {
      const float* from = image.pixel(int(nearest.at(x, y, 0)), int(nearest.at(x, y, 1)));
      std::copy_n(from, image.channels, out.pixel(x, y));
    }
  return out;
}

void check_layer(const Shot& shot, const ShotLayer& layer) {
  if (layer.masks.size() != shot.frames.size())
    throw ValueError(concat("layer '", layer.name, "' has ", layer.masks.size(), " mask(s) for a shot of ",
                            shot.frames.size(), " frame(s)"));
  for (std::size_t t = 0; t < layer.masks.size(); ++t) {
    const ImageView& m = layer.masks[t];
    const ImageView& v = shot.frames[t].velocity_backward;
    if (m.channels != 1 || m.width != v.width || m.height != v.height)
      throw ValueError(concat("the mask of layer '", layer.name, "' at frame ", t, " is ", m.width, "x", m.height, "x",
                              m.channels, "; it must be ", v.width, "x", v.height, "x1"));
  }
  const ImageView& m = layer.style_mask;
  if (!m.empty() && (m.width != shot.style.width || m.height != shot.style.height || m.channels != 1))
    throw ValueError(concat("the exemplar mask of layer '", layer.name, "' is ", m.width, "x", m.height, "x",
                            m.channels, "; it must be the exemplar's ", shot.style.width, "x", shot.style.height, "x1"));
  if (!layer.style.empty() && (layer.style.width != shot.style.width || layer.style.height != shot.style.height ||
                               layer.style.channels != shot.style.channels))
    throw ValueError(concat("the painting of layer '", layer.name, "' is ", layer.style.width, "x",
                            layer.style.height, "x", layer.style.channels, " but the shared painting is ",
                            shot.style.width, "x", shot.style.height, "x", shot.style.channels,
                            " (it is painted over the same exemplar render)"));
}

}  // namespace

Image extend_from_mask(const ImageView& image, const ImageView& mask) {
  return pick_nearest(image, nearest_mask_pixel(mask, "layer mask"));
}

Shot layer_shot(const Shot& shot, const ShotLayer& layer, std::deque<Image>& keep, bool extrapolate) {
  return layer_shot(shot, layer, [&](Image&& image) { return keep.emplace_back(std::move(image)).view(); }, extrapolate);
}

Shot layer_shot(const Shot& shot, const ShotLayer& layer, const ImageKeeper& keep, bool extrapolate) {
  check_layer(shot, layer);
  Shot out = shot;
  if (!layer.style.empty()) out.style = layer.style;
  if (!layer.style_mask.empty()) out.style_mask = layer.style_mask;
  if (!extrapolate) return out;
  const std::size_t n = shot.frames.size();
  for (std::size_t t = 0; t < n; ++t) {
    const Image nearest = nearest_mask_pixel(layer.masks[t], concat("the mask of layer '", layer.name, "'"));
    ShotFrame& f = out.frames[t];
    for (ImageView* v : {&f.velocity_backward, &f.velocity_forward}) *v = keep(pick_nearest(*v, nearest));
    for (ImageView& g : f.guides) g = keep(pick_nearest(g, nearest));
    if (!f.orientation.empty()) f.orientation = keep(pick_nearest(f.orientation, nearest));
  }
  // χ of the layer alone, from its own (extrapolated) motion; the shot's
  // ends keep theirs (no neighbour there).
  for (std::size_t t = 0; t < n; ++t) {
    ShotFrame& f = out.frames[t];
    if (t > 0)
      f.occlusion_backward = keep(occlusion_backward(f.velocity_backward, out.frames[t - 1].velocity_forward));
    if (t + 1 < n)
      f.occlusion_forward = keep(occlusion_forward(f.velocity_forward, out.frames[t + 1].velocity_backward));
  }
  return out;
}

std::vector<int> depth_order(const ImageView& depth, const std::vector<ImageView>& masks) {
  std::vector<float> median(masks.size(), 0.0f);
  std::vector<bool> seen(masks.size(), false);
  for (std::size_t i = 0; i < masks.size(); ++i) {
    if (masks[i].width != depth.width || masks[i].height != depth.height)
      throw ValueError(concat("layer mask ", i, " is ", masks[i].width, "x", masks[i].height, " but the depth is ",
                              depth.width, "x", depth.height));
    std::vector<float> z;
    for (std::size_t p = 0; p < masks[i].pixel_count(); ++p)
      if (masks[i].data[p] > 0.5f) z.push_back(depth.data[p * std::size_t(depth.channels)]);
    if (z.empty()) continue;
    std::nth_element(z.begin(), z.begin() + std::ptrdiff_t(z.size() / 2), z.end());
    median[i] = z[z.size() / 2], seen[i] = true;
  }
  std::vector<int> order(masks.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    if (seen[a] != seen[b]) return !seen[a];  // empty layers at the back
    return seen[a] && median[a] > median[b];  // farther first
  });
  return order;
}

Image composite_layers(const std::vector<ImageView>& images, const std::vector<ImageView>& masks,
                       const std::vector<int>& back_to_front) {
  if (images.empty() || images.size() != masks.size() || back_to_front.size() != images.size())
    throw ValueError(concat("compositing needs one mask per layer and an order of them all (", images.size(),
                            " image(s), ", masks.size(), " mask(s), ", back_to_front.size(), " in the order)"));
  for (std::size_t i = 0; i < images.size(); ++i)
    if (images[i].width != images[0].width || images[i].height != images[0].height ||
        images[i].channels != images[0].channels || masks[i].width != images[0].width ||
        masks[i].height != images[0].height || masks[i].channels != 1)
      throw ValueError(concat("layer ", i, "'s image or mask differs in size from layer 0's"));
  Image out = Image::copy_of(images[std::size_t(back_to_front[0])]);
  const int c = out.channels();
  for (std::size_t k = 1; k < back_to_front.size(); ++k) {
    const ImageView& layer = images[std::size_t(back_to_front[k])];
    const ImageView& mask = masks[std::size_t(back_to_front[k])];
    for (std::size_t p = 0; p < out.pixel_count(); ++p) {
      const float a = std::clamp(mask.data[p], 0.0f, 1.0f);
      float* o = out.data() + p * std::size_t(c);
      for (int i = 0; i < c; ++i) o[i] = a * layer.data[p * std::size_t(c) + i] + (1 - a) * o[i];
    }
  }
  return out;
}

}  // namespace tempera

#include "tempera/methods/noisy/render_medium.hpp"

#include <algorithm>

#include "tempera/engine/pyramid.hpp"
#include "tempera/engine/rng.hpp"

namespace tempera {
namespace {

// Stream of the grain's random numbers, apart from the synthesis' streams.
constexpr std::uint64_t kGrainStream = 0x67726169ull;  // "grai"

}  // namespace

Image render_medium(const ImageView& colours, std::uint64_t seed) {
  Image noise(colours.width, colours.height, 1);
  Rng rng(seed, kGrainStream);
  for (std::size_t i = 0; i < noise.pixel_count(); ++i) noise.data()[i] = rng.uniform() - 0.5f;
  const Image tooth = box_blur(noise.view(), 3), clumps = box_blur(noise.view(), 9);
  // Uniform noise has a deviation of 0.29; a 3-px box leaves 0.096 of it and a 9-px box 0.032.
  Image out = Image::copy_of(colours);
  const int colour = std::min(colours.channels, 3);
  for (std::size_t i = 0; i < out.pixel_count(); ++i) {
    const float g = 1.0f + tooth.data()[i] + 2.0f * clumps.data()[i];
    for (int c = 0; c < colour; ++c) {
      float& v = out.data()[i * std::size_t(colours.channels) + std::size_t(c)];
      v = std::clamp(v * g, 0.0f, 1.0f);
    }
  }
  return out;
}

}  // namespace tempera

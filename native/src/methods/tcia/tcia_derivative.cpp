#include "tempera/methods/tcia/tcia_derivative.hpp"

#include "tempera/engine/error.hpp"
#include "tempera/engine/motion.hpp"
#include "tempera/engine/patch_distance.hpp"  // sample_bilinear
#include "tempera/engine/solver.hpp"

namespace tempera {

Image matched_guide(const Solver& solver, int level, const OffsetField& field,
                    const std::vector<ImageView>& exemplar_guides) {
  const SourceLayout& layout = solver.layout(level);
  if (exemplar_guides.size() != layout.rects.size())
    throw ValueError(concat(exemplar_guides.size(), " exemplar guides for ", layout.rects.size(), " exemplars"));
  const int channels = exemplar_guides.front().channels;
  Image out(field.width, field.height, channels);
  for (std::size_t i = 0; i < field.x.size(); ++i) {
    const ExemplarMatch m = solver.match(level, field, i);
    const ImageView& g = exemplar_guides[std::size_t(m.exemplar)];
    const SourceRect& rect = layout.rects[std::size_t(m.exemplar)];
    // Level pixel centres -> full-size pixel centres.
    const float x = (m.x + 0.5f) * float(g.width) / float(rect.width) - 0.5f;
    const float y = (m.y + 0.5f) * float(g.height) / float(rect.height) - 0.5f;
    sample_bilinear(g.data, g.width, g.height, g.channels, g.channels, x, y, out.data() + i * channels);
  }
  return out;
}

Image derivative_target(const Image& guide, const Image& previous_guide, const Image& previous_matched,
                        const ImageView& velocity) {
  Image mismatch = Image::copy_of(previous_matched.view());
  for (std::size_t i = 0; i < mismatch.pixel_count() * std::size_t(mismatch.channels()); ++i)
    mismatch.data()[i] -= previous_guide.data()[i];
  Image out = warp_backward(mismatch.view(), velocity);
  for (std::size_t i = 0; i < out.pixel_count() * std::size_t(out.channels()); ++i) out.data()[i] += guide.data()[i];
  return out;
}

}  // namespace tempera

#include "tempera/methods/rigid/stroke_resynthesis.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>

#include "tempera/app/image_io.hpp"
#include "tempera/engine/distance_transform.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/engine/rng.hpp"

namespace tempera {
namespace {

// Plain nearest neighbours: a usage term would push the exemplar's ink
// patches into the blank paper (most of a frame is blank), which is exactly
// what the guide must prevent.
constexpr int kPatchSize = 5;

struct Box {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) x [y0, y1)
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
};

// The box around the ink (alpha > 1e-3) of `rgba`, widened by `margin` and
// kept inside the image; empty when there is no ink.
Box ink_box(const ImageView& rgba, int margin) {
  Box b{rgba.width, rgba.height, -1, -1};
  for (int y = 0; y < rgba.height; ++y)
    for (int x = 0; x < rgba.width; ++x)
      if (rgba.at(x, y, 3) > 1e-3f) b = {std::min(b.x0, x), std::min(b.y0, y), std::max(b.x1, x), std::max(b.y1, y)};
  if (b.x1 < 0) return {};
  return {std::max(0, b.x0 - margin), std::max(0, b.y0 - margin), std::min(rgba.width, b.x1 + margin + 1),
          std::min(rgba.height, b.y1 + margin + 1)};
}

Image crop(const ImageView& image, const Box& b) {
  Image out(b.width(), b.height(), image.channels);
  for (int y = 0; y < b.height(); ++y)
    std::copy_n(image.pixel(b.x0, b.y0 + y), std::size_t(b.width()) * std::size_t(image.channels), out.pixel(0, y));
  return out;
}

// Colour times alpha, alpha kept: what the engine blends without halos.
Image premultiplied(const ImageView& rgba) {
  Image out = Image::copy_of(rgba);
  for (std::size_t i = 0; i < out.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c) out.data()[4 * i + std::size_t(c)] *= out.data()[4 * i + 3];
  return out;
}

double segment_distance(double x, double y, const std::array<double, 2>& a, const std::array<double, 2>& b) {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double t = std::clamp(((x - a[0]) * dx + (y - a[1]) * dy) / std::max(dx * dx + dy * dy, 1e-9), 0.0, 1.0);
  return std::hypot(x - (a[0] + t * dx), y - (a[1] + t * dy));
}

}  // namespace

Image stroke_guide(const ImageView& rgba, float d_max) {
  Image ink(rgba.width, rgba.height, 1);
  for (std::size_t i = 0; i < ink.pixel_count(); ++i) ink.data()[i] = rgba.data[4 * i + 3] > kStrokeInk ? 1.0f : 0.0f;
  Image g = line_distance(ink.view(), d_max);
  for (std::size_t i = 0; i < g.pixel_count(); ++i) g.data()[i] = 1.0f - g.data()[i];
  return g;
}

Image resynthesize_strokes(const ImageView& drawing, const ImageView& exemplar, float d_max, float weight,
                           std::uint64_t seed, const ProgressCallback& progress) {
  if (drawing.channels != 4) throw ValueError(concat("the drawing must be an RGBA image, got ", drawing.channels, " channels"));
  if (exemplar.channels != 4)
    throw ValueError(concat("the stroke exemplar must be an RGBA image, got ", exemplar.channels, " channels"));
  bool has_ink = false;
  for (std::size_t i = 0; i < exemplar.pixel_count() && !has_ink; ++i) has_ink = exemplar.data[4 * i + 3] > kStrokeInk;
  if (!has_ink) throw ValueError("the stroke exemplar has no ink (alpha > 0.5)");
  Image out(drawing.width, drawing.height, 4);
  const Box box = ink_box(drawing, int(std::ceil(d_max)) + kPatchSize);
  if (box.width() <= 0) return out;
  const Image target = crop(drawing, box);
  const Image style = premultiplied(exemplar);
  const Image source_guide = stroke_guide(exemplar, d_max), target_guide = stroke_guide(target.view(), d_max);
  SynthesisInput in;
  in.style = style.view();
  if (weight > 0) {
    in.guides.add("guide0", source_guide.view(), target_guide.view(), weight);
    in.target_weight_maps.emplace_back();
  }
  in.target_width = box.width(), in.target_height = box.height();
  SynthesisOptions options;
  options.usage = PatchUsage::None;
  options.patch_size = kPatchSize;
  options.em_tolerance = 0;  // every iteration (the early stop is measured for StyLit only)
  options.seed = seed;
  const Image made = synthesize(in, options, progress).image;
  for (int y = 0; y < box.height(); ++y)
    for (int x = 0; x < box.width(); ++x) {
      const float* m = made.pixel(x, y);
      float* o = out.pixel(box.x0 + x, box.y0 + y);
      const float a = std::clamp(m[3], 0.0f, 1.0f);
      for (int c = 0; c < 3; ++c) o[c] = std::clamp(m[c], 0.0f, 1.0f) / std::max(a, 1e-6f);
      o[3] = a;
    }
  return out;
}

Image generated_stroke_exemplar(int size, float width, std::uint64_t seed) {
  Rng rng(seed, 0x5713E);
  const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * double(rng.uniform()); };
  Image alpha(size, size, 1);
  constexpr double kPi = 3.14159265358979323846;
  constexpr int kPoints = 48;
  for (int stroke = 0; stroke < 7; ++stroke) {
    const double cx = uniform(0.25, 0.75) * size, cy = uniform(0.25, 0.75) * size;
    const double radius = uniform(0.12, 0.3) * size, squash = uniform(0.6, 1.0);
    const double start = uniform(0, 2 * kPi), sweep = uniform(1.2, 2 * kPi);
    std::array<double, 2> previous{};
    for (int k = 0; k < kPoints; ++k) {
      const double t = start + sweep * k / (kPoints - 1);
      const std::array<double, 2> point{cx + radius * std::cos(t), cy + radius * std::sin(t) * squash};
      if (k > 0) {
        const double pressure = 0.6 + 0.4 * std::sin(kPi * (k - 1) / (kPoints - 1));
        for (int y = 0; y < size; ++y)
          for (int x = 0; x < size; ++x) {
            const double cover = width * pressure / 2 + 0.5 - segment_distance(x, y, previous, point);
            float& a = alpha.at(x, y, 0);
            a = std::max(a, float(std::clamp(cover, 0.0, 1.0)));
          }
      }
      previous = point;
    }
  }
  Image rgba(size, size, 4);
  for (std::size_t i = 0; i < rgba.pixel_count(); ++i) {
    float* p = rgba.data() + 4 * i;
    std::copy(std::begin(kGeneratedStrokeColour), std::end(kGeneratedStrokeColour), p);
    p[3] = alpha.data()[i] * float(uniform(0.55, 1.0));  // the dry brush's grain
  }
  return rgba;
}

Image read_stroke_exemplar(const std::string& path) {
  const Image image = read_image(path);
  if (image.channels() == 4) return image;
  Image rgba(image.width(), image.height(), 4);
  const int c = image.channels();
  for (std::size_t i = 0; i < rgba.pixel_count(); ++i) {
    const float* p = image.data() + std::size_t(c) * i;
    const float grey = c >= 3 ? (p[0] + p[1] + p[2]) / 3.0f : p[0];
    rgba.data()[4 * i + 3] = std::clamp(1.0f - grey, 0.0f, 1.0f);
  }
  return rgba;
}

Image load_stroke_exemplar(const std::string& spec) {
  if (spec == kGeneratedStrokes) return generated_stroke_exemplar();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(spec, ec))
    throw FileNotFoundError(concat("the stroke exemplar '", spec, "' does not exist (an RGBA image of strokes, or '",
                                   kGeneratedStrokes, "')"));
  return read_stroke_exemplar(spec);
}

}  // namespace tempera

#include "tempera/methods/noisy/noisy.hpp"

#include <algorithm>
#include <cmath>

#include "tempera/engine/error.hpp"
#include "tempera/engine/pyramid.hpp"
#include "tempera/engine/rng.hpp"
#include "tempera/engine/solver.hpp"

namespace tempera {
namespace {

constexpr double kRatio = 0.85;  // the paper's sampling-rate ratio between levels

// An exemplar layer under the frame's MLS map (no map: the layer as it is).
Image warped(const ImageView& layer, const Image& deformation) {
  return deformation.empty() ? Image::copy_of(layer) : warp_by_map(layer, deformation.view());
}

}  // namespace

SynthesisOptions noisy_defaults() {
  SynthesisOptions o;
  o.patch_size = 7;
  o.em_iterations = 4;   // "4 iterations of search and vote" per level (§4)
  o.pm_iterations = 2;   // "8 PatchMatch iterations at each pyramid level": 2 per search x 4 searches
  o.em_tolerance = 0;    // every iteration: the paper's schedule (the early stop is measured for StyLit only)
  o.usage = PatchUsage::None;
  o.output = OutputMode::Mode;  // "the mode of colours" (§3.2)
  o.level_ratio = kRatio;
  o.guide_variance = 1.0;
  return o;
}

int noisy_levels(float noise) {
  if (!(noise > 1.0f)) return 1;
  return 1 + int(std::ceil(std::log(double(noise)) / std::log(1.0 / kRatio) - 1e-9));
}

std::vector<float> noisy_box_widths(float noise) {
  const int m = noisy_levels(noise);
  std::vector<float> widths(std::size_t(m), 1.0f);
  for (int l = 1; l < m; ++l) widths[std::size_t(l)] = float(std::pow(double(noise), double(l) / (m - 1)));
  return widths;
}

namespace {

// The solver's rule (solver.cpp): the coarsest level keeps a patch and a pixel each side.
bool holds_a_patch(int width, int height, int levels, int patch_size) {
  const auto [w, h] = level_sizes(width, height, levels, kRatio).back();
  return w >= patch_size + 2 && h >= patch_size + 2;
}

}  // namespace

void validate_noisy_options(const NoisyOptions& o) {
  if (!std::isfinite(o.noise) || o.noise < 0 || o.noise > kMaxNoise)
    throw ValueError(concat("noise (the low-pass width f) must be in [0, ", kMaxNoise, "] pixels, got ", o.noise,
                            ": f needs 1 + ceil(ln f / ln(1 / 0.85)) pyramid levels, and 16 are the engine's most"));
  validate_fields(o, noisy_option_table());
}

float noisy_max_noise(int width, int height, int patch_size) {
  if (!holds_a_patch(width, height, 1, patch_size)) return 0.0f;
  // f to 0.1 px, downwards from the largest: noisy_levels grows with f.
  for (int tenths = int(kMaxNoise * 10 + 0.5f); tenths > 10; --tenths) {
    const float f = float(tenths) / 10.0f;
    if (holds_a_patch(width, height, noisy_levels(f), patch_size)) return f;
  }
  return 1.0f;  // only f <= 1, which is no noise
}

void check_noisy_exemplar_size(float noise, int width, int height, int patch_size) {
  if (!(noise > 1.0f) || holds_a_patch(width, height, noisy_levels(noise), patch_size)) return;
  const auto [w, h] = level_sizes(width, height, noisy_levels(noise), kRatio).back();
  throw ValueError(concat("noise ", noise, " is too coarse for the ", width, "x", height, " exemplar: it needs ",
                          noisy_levels(noise), " pyramid levels (each 0.85 of the last), and the smallest, ", w, "x",
                          h, " pixels, cannot hold a patch of ", patch_size, " pixels; use a noise of at most ",
                          noisy_max_noise(width, height, patch_size), " with it, or a larger exemplar"));
}

std::uint64_t noisy_frame_seed(std::uint64_t seed, int frame) { return mix64(seed ^ mix64(std::uint64_t(std::int64_t(frame)) + 0x6E6F697379ull)); }

Image exemplar_deformation(int width, int height, const NoisyOptions& o, int frame) {
  if (!o.deform) return {};
  const float scale = float(std::sqrt(double(width) * height / 1e6));
  const MlsLattice lattice = random_lattice(width, height, o.lattice_spacing * scale, o.shift_min * scale,
                                            o.shift_max * scale, noisy_frame_seed(o.synthesis.seed, frame));
  return mls_backward_map(lattice, width, height);
}

Image deform_exemplar(const ImageView& style, const NoisyOptions& o, int frame) {
  return warped(style, exemplar_deformation(style.width, style.height, o, frame));
}

Image dihedral_copy(const ImageView& image, int k) {
  Image out = Image::copy_of(image);
  if (k & 1)
    for (int y = 0; y < out.height(); ++y)
      for (int x = 0; x < out.width() / 2; ++x)
        for (int c = 0; c < out.channels(); ++c) std::swap(out.at(x, y, c), out.at(out.width() - 1 - x, y, c));
  for (int turn = 0; turn < (k >> 1) % 4; ++turn) {
    Image turned(out.height(), out.width(), out.channels());  // (x, y) -> (h - 1 - y, x)
    for (int y = 0; y < out.height(); ++y)
      for (int x = 0; x < out.width(); ++x)
        for (int c = 0; c < out.channels(); ++c) turned.at(out.height() - 1 - y, x, c) = out.at(x, y, c);
    out = std::move(turned);
  }
  return out;
}

namespace {

// The dihedral copies besides the exemplar itself that the options ask for.
std::vector<int> dihedral_copies(const NoisyOptions& o) {
  std::vector<int> k;
  for (int c = 1; c < 8; ++c)
    if (((c & 1) == 0 || o.reflections) && ((c >> 1) == 0 || o.rotations)) k.push_back(c);
  return k;
}

// Rotations and reflections of P (eq. 1) as further exemplars: each copy
// turns the exemplar and its guide sources alike (a box blur commutes with
// them, so the low-frequency sources stay h_f * copy).
void add_dihedral_exemplars(SynthesisInput& in, const NoisyOptions& o, std::vector<Image>& keep) {
  const std::vector<int> copies = dihedral_copies(o);
  keep.reserve(copies.size() * (1 + in.guides.layers().size()));  // the views below must not move
  for (int k : copies) {
    Exemplar e;
    keep.push_back(dihedral_copy(in.style, k));
    e.style = keep.back().view();
    for (const GuideLayer& layer : in.guides.layers()) {
      keep.push_back(dihedral_copy(layer.source, k));
      e.guides.push_back(keep.back().view());
    }
    in.exemplars.push_back(e);
  }
}

// The level at which a pixel with width f_p joins the synthesis: the
// coarsest whose f_bar <= f_p; -1 below 1 (the pixel copies R).
int join_level(const std::vector<float>& widths, float fp) {
  if (fp < 1.0f) return -1;
  int l = 0;
  while (l + 1 < int(widths.size()) && widths[std::size_t(l) + 1] <= fp + 1e-6f) ++l;
  return l;
}

void validate_guides(const ImageView& style, const ImageView& reference, const std::vector<NoisyGuide>& guides) {
  if (guides.empty())
    throw ValueError("guided noise (noise_guides > 0) needs the light-path guides of the exemplar and of the frame");
  for (const NoisyGuide& g : guides) {
    require_same_size(g.source, concat("exemplar guide '", g.name, "'"), style, "exemplar");
    require_same_size(g.target, concat("frame guide '", g.name, "'"), reference, "reference frame");
    if (g.source.channels != g.target.channels)
      throw ValueError(concat("guide '", g.name, "' has ", g.source.channels, " channels for the exemplar but ",
                              g.target.channels, " for the frame"));
    if (!std::isfinite(g.weight) || g.weight < 0) throw ValueError(concat("guide '", g.name, "' has a bad weight"));
  }
}

void validate(const ImageView& style, const ImageView& reference, const NoisyOptions& o, const ImageView& map) {
  require_nonempty(style, "exemplar");
  require_nonempty(reference, "reference frame");
  if (style.channels != reference.channels)
    throw ValueError(concat("the reference frame has ", reference.channels, " channels but the exemplar has ",
                            style.channels));
  if (!std::isfinite(o.noise_guides) || o.noise_guides < 0)
    throw ValueError(concat("noise_guides (the guided-noise weight) must be >= 0, got ", o.noise_guides));
  validate_noisy_options(o);
  if (!map.empty()) {
    if (map.channels != 1) throw ValueError("the noise map must have 1 channel");
    require_same_size(map, "noise map", reference, "reference frame");
    require_finite(map, "noise map");
  }
}

// Eq. 2 as guide pairs, h_w * S against h_w * R, weight `consistency`. With a
// local map, eq. 2's h_f becomes h_{f_p} (§3.3): one pair per level at which
// pixels join, with the f_bar of that level, each weighted by a map of its
// pixels, so a calm region is held as firmly as a global run at its f.
void add_low_frequency_guides(SynthesisInput& in, const ImageView& exemplar, const ImageView& reference,
                              const NoisyOptions& o, float f, const ImageView& noise_map, std::vector<Image>& keep) {
  const std::vector<float> widths = noisy_box_widths(f);
  std::vector<int> join;  // per pixel: the level it joins at, -1 = a copy of R
  if (!noise_map.empty())
    for (std::size_t i = 0; i < noise_map.size(); ++i) join.push_back(join_level(widths, o.noise * noise_map.data[i]));
  std::vector<int> levels(join.begin(), join.end());
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  levels.erase(std::remove(levels.begin(), levels.end(), -1), levels.end());
  keep.reserve(3 * std::max<std::size_t>(1, levels.size()));
  if (levels.size() <= 1) {  // one width everywhere: the global term
    keep.push_back(box_blur(exemplar, f));
    keep.push_back(box_blur(reference, f));
    in.guides.add("low_frequencies", keep[0].view(), keep[1].view(), o.consistency);
    return;
  }
  for (int l : levels) {
    const float w = widths[std::size_t(l)];
    keep.push_back(box_blur(exemplar, w));
    keep.push_back(box_blur(reference, w));
    Image weight(reference.width, reference.height, 1);
    for (std::size_t i = 0; i < join.size(); ++i) weight.data()[i] = join[i] == l ? 1.0f : 0.0f;
    keep.push_back(std::move(weight));
    const std::size_t k = keep.size();
    in.guides.add(concat("low_frequencies_", l), keep[k - 3].view(), keep[k - 2].view(), o.consistency);
    in.target_weight_maps.push_back(keep[k - 1].view());
  }
}

// Guided noise: each light-path guide pair, the exemplar's side warped by
// the frame's MLS map like S (so a deformed patch keeps its light), weight
// StyLit's times noise_guides. The solver low-passes and resamples the guides
// per level as it does S and R.
void add_light_path_guides(SynthesisInput& in, const std::vector<NoisyGuide>& guides, const Image& deformation,
                           const NoisyOptions& o, std::vector<Image>& keep) {
  keep.reserve(guides.size());
  for (const NoisyGuide& g : guides) {
    if (!(g.weight > 0)) continue;
    keep.push_back(warped(g.source, deformation));
    in.guides.add(g.name, keep.back().view(), g.target, g.weight * o.noise_guides);
  }
}

}  // namespace

Image noisy_frame(const ImageView& style, const ImageView& reference, int frame, const NoisyOptions& o,
                  const ImageView& noise_map, const ProgressCallback& progress, const std::vector<NoisyGuide>& guides) {
  validate(style, reference, o, noise_map);
  const bool guided = o.noise_guides > 0;
  if (guided) validate_guides(style, reference, guides);
  // With a map, f_p = f * map(p): the map says where the noise goes (1 =
  // the slider's amount, 0 = R as it is).
  const float f = noise_map.empty() ? o.noise : o.noise * std::max(0.0f, *std::max_element(noise_map.data, noise_map.data + noise_map.size()));
  if (!(f > 1.0f)) return Image::copy_of(reference);  // no noise anywhere: R itself
  check_noisy_exemplar_size(f, style.width, style.height, o.synthesis.patch_size);
  const Image deformation = exemplar_deformation(style.width, style.height, o, frame);
  const Image exemplar = warped(style, deformation);
  SynthesisInput in;
  in.style = exemplar.view();
  in.target_width = reference.width;
  in.target_height = reference.height;
  in.reference = reference;
  std::vector<Image> low_frequency_images;  // kept alive for the guides' views
  if (o.consistency > 0) add_low_frequency_guides(in, exemplar.view(), reference, o, f, noise_map, low_frequency_images);
  std::vector<Image> guide_images;  // the warped exemplar guides, kept alive likewise
  if (guided) add_light_path_guides(in, guides, deformation, o, guide_images);
  std::vector<Image> dihedral_images;  // kept alive for the exemplars' views
  add_dihedral_exemplars(in, o, dihedral_images);
  SynthesisOptions opt = o.synthesis;
  opt.levels = noisy_levels(f);
  opt.level_ratio = kRatio;
  // Eq. 4 with a box h: area resampling to the level's size is already
  // h_f_bar * S (down)f_bar; a further box would low-pass twice (measured:
  // half the noise at f = 4.3).
  opt.level_box_widths.clear();
  opt.seed = noisy_frame_seed(o.synthesis.seed, frame);
  // The local noise map: per level, pixels whose f_p is below that level's
  // f_bar are held at R (blurred and downsampled like it).
  std::vector<Image> reference_levels;
  if (!noise_map.empty()) reference_levels = build_pyramid(reference, opt.levels, kRatio, {});
  const Solver solver(in, opt);
  const std::vector<float> widths = noisy_box_widths(f);  // f_bar per level, for the local map
  LevelResult r;
  for (int l = solver.coarsest(); l >= 0; --l) {
    Image mask;
    LevelStart start;
    OffsetField up;
    if (l < solver.coarsest()) {
      up = solver.resample(r.field, l + 1, l);
      start.field = &up;
    }
    Image joining;
    if (!noise_map.empty()) {
      // f_p at this level's size (area-averaged).
      const Image fp = resize_area(noise_map, solver.target_width(l), solver.target_height(l));
      const Image& held = reference_levels[std::size_t(l)];
      mask = Image(fp.width(), fp.height(), 1);
      std::vector<int> join(fp.pixel_count());
      for (std::size_t i = 0; i < join.size(); ++i) {
        join[i] = join_level(widths, o.noise * fp.data()[i]);
        mask.data()[i] = join[i] < 0 || join[i] < l ? 1.0f : 0.0f;
      }
      start.fixed_mask = &mask;
      start.fixed_values = &held;
      // Pixels that join here start from R (their field is a placeholder);
      // the others from the B' voted from the upsampled field.
      if (l < solver.coarsest()) {
        joining = Image(fp.width(), fp.height(), 1);
        for (std::size_t i = 0; i < join.size(); ++i) joining.data()[i] = join[i] == l ? 1.0f : 0.0f;
        start.image = &held;
        start.image_mask = &joining;
      }
    }
    const double done = double(solver.coarsest() - l) / solver.levels();
    r = solver.solve_level(l, start, [&](double x) { return !progress || progress(done + x / solver.levels()); });
  }
  return std::move(r.image);
}

}  // namespace tempera

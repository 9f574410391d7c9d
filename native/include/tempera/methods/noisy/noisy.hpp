#pragma once
// Color Me Noisy (Fišer et al. 2014; thesis ch. 4) as a method on the engine:
// one frame T_i from a coherent, noise-free frame R_i that already looks like
// the medium S. Below the low-pass width f the output follows R; above it the
// texture is synthesized again, every frame, from a freshly deformed S, so
// the medium's fine texture "boils" by an amount the artist sets with f.
//
//  - the exemplar is pre-deformed by rigid MLS on a random lattice (50 px
//    spacing, nodes moved 15-25 px, both scaled with sqrt(pixels / 1 Mpix)),
//    fresh every frame (§3.2);
//  - pyramid ratio 0.85 with M = 1 + ceil(ln f / ln(1 / 0.85)) levels and the
//    box widths f_bar(l) = f^(l / (M - 1)) (l = 0 finest: 1; coarsest: f),
//    for the exemplar and for R alike (eq. 4); the coarsest level starts
//    from h_f * R (the engine's reference), and the low-frequency term of
//    eq. 2, |h_f * R - h_f * T|^2, is a guide pair (h_f * S against h_f * R)
//    at every level: the paper only initializes from R, which let the large
//    shapes drift from R's at every f in our measurements (docs/noisy.md);
//  - 4 EM iterations per level with 2 PatchMatch sweeps each (the paper's "8
//    PatchMatch iterations at each pyramid level"), 7 x 7 patches,
//    weighted-mode voting, no usage control (§4);
//  - a fresh random seed per frame, mix(seed, frame), so reruns repeat;
//  - optional rotations and reflections of P (eq. 1): the exemplar's dihedral
//    copies join the source set as further exemplars;
//  - a local noise map f_p (§3.3): pixel p joins the synthesis at the first
//    level whose f_bar <= f_p and copies R before; f_p < 1 copies R outright;
//  - optional guided noise (the thesis's future work): StyLit's light-path
//    guides of the exemplar render (warped by the same MLS map as S) against
//    those of the frame join as guide pairs at every level, so the search
//    takes its patches where the light matches (docs/noisy.md).
#include <cstdint>
#include <string>
#include <vector>

#include "tempera/engine/image.hpp"
#include "tempera/methods/noisy/mls.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/engine/synthesis.hpp"

namespace tempera {

// The largest f: its M = 1 + ceil(ln f / ln(1 / 0.85)) = 16 levels are the engine's most.
constexpr double kMaxNoise = 11.4;

struct NoisyOptions {
  float noise = 2.2f;          // f, the low-pass width in pixels; <= 1 = no noise (the output is R)
  float lattice_spacing = 50;  // MLS lattice at 1 Mpix (scaled with sqrt(pixels / 1 Mpix))
  float shift_min = 15, shift_max = 25;
  bool deform = true;          // the MLS pre-deformation (off only for the paper's ablation)
  float consistency = 2.75f;    // weight of the low-frequency term (eq. 2) as a guide pair
  bool rotations = false;      // the exemplar's quarter turns join the source set (eq. 1: P "rotated")
  bool reflections = false;    // its mirror images too (with rotations: all 8 dihedral copies)
  float noise_guides = 0;      // guided noise: scale of StyLit's light-path guide weights; 0 = off
  SynthesisOptions synthesis;  // patch 7, mode voting, 4 EM x 2 PM per level, usage none (noisy_defaults())
};

// The engine options Color Me Noisy uses, before its pyramid is set per f.
SynthesisOptions noisy_defaults();
inline const auto& noisy_option_table() {
  using N = NoisyOptions;
  static const auto table = std::make_tuple(
      field(&N::noise, "noise", "noise",
            "the low-pass width f in pixels: how coarse the boiling is (the paper tests 1.3 - 4.3; 0 = off); "
            "at most 11.4, whose 16 pyramid levels are the engine's most, and less for a small exemplar",
            0, kMaxNoise),
      field(&N::lattice_spacing, "lattice_spacing", "lattice-spacing",
            "MLS lattice spacing in pixels at 1 Mpix (scaled with the frame's size); 50 in the paper", 1, 10000),
      field(&N::shift_min, "shift_min", "shift-min", "least move of an MLS lattice node, px at 1 Mpix (15)", 0, 10000),
      field(&N::shift_max, "shift_max", "shift-max", "largest move of an MLS lattice node, px at 1 Mpix (25)", 0, 10000),
      field(&N::deform, "deform", "deform", "pre-deform the exemplar every frame (off only for comparisons)"),
      field(&N::consistency, "consistency", "consistency",
            "weight of the low-frequency term |h_f*R - h_f*T|^2: how firmly the large shapes stay R's (2.75)", 0, 1e6),
      field(&N::rotations, "rotations", "rotations",
            "also copy patches from the exemplar turned by 90, 180 and 270 degrees (for media without a direction)"),
      field(&N::reflections, "reflections", "reflections",
            "also copy patches from the exemplar's mirror image (and its turns, with rotations)"),
      field(&N::noise_guides, "noise_guides", "noise-guides",
            "guided noise: keep StyLit's light-path guides at every level, their weights times this "
            "(0 = off; the panel uses 0.5, docs/noisy.md); needs both guide caches", 0, 1e6));
  return table;
}

inline NoisyOptions default_noisy_options() {
  NoisyOptions o;
  o.synthesis = noisy_defaults();
  return o;
}

// Levels of the noise pyramid for f: M = 1 + ceil(ln f / ln(1 / 0.85)).
int noisy_levels(float noise);
// ValueError for an option out of its range; noise's says why its range ends at kMaxNoise.
void validate_noisy_options(const NoisyOptions& options);
// f_bar(l) = f^(l / (M - 1)), l = 0 (finest) .. M - 1.
std::vector<float> noisy_box_widths(float noise);
// The largest f (to 0.1 px, at most kMaxNoise) whose coarsest level of a
// width x height exemplar still holds a patch of patch_size with the solver's
// margin; 0 when even one level does not.
float noisy_max_noise(int width, int height, int patch_size);
// ValueError naming the largest f that works when `noise` is too coarse for
// an exemplar of width x height (checked before any work, in the noise's words).
void check_noisy_exemplar_size(float noise, int width, int height, int patch_size);

// The per-frame seed: mix(seed, frame).
std::uint64_t noisy_frame_seed(std::uint64_t seed, int frame);

// The MLS pre-deformation of frame `frame` as a backward map (x, y per
// pixel) over a width x height exemplar; empty when options.deform is off.
Image exemplar_deformation(int width, int height, const NoisyOptions& options, int frame);

// The exemplar `style` deformed for frame `frame` (the MLS pre-deformation).
Image deform_exemplar(const ImageView& style, const NoisyOptions& options, int frame);

// One light-path guide pair for guided noise: the exemplar render's guide
// (the exemplar's size, undeformed: noisy_frame warps it like S), the
// frame's (R's size), both tone-mapped, and StyLit's weight, which
// options.noise_guides scales.
struct NoisyGuide {
  std::string name;
  ImageView source, target;
  float weight = 1;
};

// The dihedral copy `k` of an image: bit 0 mirrors x, bits 1-2 count the
// quarter turns clockwise after it (k = 0: the image itself).
Image dihedral_copy(const ImageView& image, int k);

// One noisy frame. `reference` is R_i (any size; the exemplar's channels);
// `noise_map` (optional, R's size, 1 channel) holds f_p per pixel. `guides`
// are used when options.noise_guides > 0 (and then required).
Image noisy_frame(const ImageView& style, const ImageView& reference, int frame, const NoisyOptions& options,
                  const ImageView& noise_map = {}, const ProgressCallback& progress = {},
                  const std::vector<NoisyGuide>& guides = {});

}  // namespace tempera

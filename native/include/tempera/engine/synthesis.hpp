#pragma once
// The synthesis engine: guided texture optimization (EM over a coarse-to-fine
// pyramid, PatchMatch for the E-step, voting for the M-step). synthesize() is
// the whole solve in one call; methods that need more (warm starts per frame,
// sweeps over a shot, constraints that change per level) drive the Solver
// (solver.hpp) level by level. See docs/engine.md.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tempera/engine/energy_term.hpp"
#include "tempera/engine/guide_stack.hpp"
#include "tempera/engine/offset_field.hpp"
#include "tempera/engine/patch_usage.hpp"
#include "tempera/engine/patchmatch.hpp"
#include "tempera/engine/source_set.hpp"
#include "tempera/engine/synthesis_options.hpp"

namespace tempera {

// Hard constraints (Bénard et al. 2013 §4.1: painted keyframe pixels): target
// pixels whose value is given. They are never searched or voted, and the
// patches of their neighbours see their values, so what is synthesized next
// to them continues them.
struct FixedPixels {
  ImageView mask;    // target size, 1 channel, > 0.5 = fixed
  ImageView values;  // target size, the style's channels: B' there
  // Optional, target size, 3 channels: exemplar index (0 = `style`, k = the
  // k-th of `exemplars` + 1), x, y in that exemplar's pixels. With it the
  // fixed pixels also vote for their neighbours, as their matches.
  ImageView matches;
  bool empty() const { return mask.empty(); }
};

struct SynthesisInput {
  ImageView style;  // A' (the exemplar), H_s x W_s x C
  GuideStack guides;
  ImageView source_mask, target_mask;                // optional, 1 channel, > 0.5 = inside
  ImageView source_orientation, target_orientation;  // optional, 1 channel, radians
  ImageView source_segments, target_segments;        // optional, 1 channel, integer labels >= 0
  // Optional, 1 channel per guide layer (or empty): per-target-pixel weight map.
  std::vector<ImageView> target_weight_maps;
  int target_width = 0, target_height = 0;  // needed only when there are no guides
  // `style` as a frame of a video exemplar (see Exemplar::sequence).
  int sequence = -1, time = 0;
  // Further exemplars of the source set besides `style`: painted keyframes,
  // the other frames of a video exemplar. Their guides pair with the layers of
  // `guides` in order.
  std::vector<Exemplar> exemplars;
  // Optional B' at the start of the coarsest level (Color Me Noisy's
  // reference animation frame), target size, the style's channels.
  ImageView reference;
  FixedPixels fixed;
  // Method terms (energy_term.hpp) besides the usage term of the options.
  EnergyTerms terms;
  // Optional: called once, as soon as the solver holds its own copy of the
  // guide images (the layers of `guides` and the exemplars' guides) and
  // before the pyramids are built. A caller that owns large guide images
  // (the CLI's decoded files) frees them here, so that they do not add to
  // the peak memory; their views are not read again.
  std::function<void()> guides_read;
  // Optional: called once before that, when the exemplars' guides (the
  // layers' sources) are read and the target's not yet: freed here, they
  // are not held while the target's are projected.
  std::function<void()> exemplar_guides_read;
  // Optional: called once the solver has built its pyramids, after which it
  // reads nothing of this input. The CLI frees its decoded style here, which
  // it held through the solve.
  std::function<void()> inputs_read;
};

struct LevelStats {
  int level = 0, width = 0, height = 0;
  std::vector<double> energy;  // mean patch distance after each search
  double search_seconds = 0, usage_seconds = 0, vote_seconds = 0;
  int usage_rounds = 0;
  std::size_t usage_wide_searches = 0;  // reversed retrieval's sources seeded at random (whole-frame search)
  // Searches of target pixels the forward search skipped as converged
  // (converged_pixels.hpp), summed over the level's EM iterations.
  std::size_t converged_skips = 0;
  double reversed_coverage = 0;  // fraction of targets placed by reversed retrieval (last iteration)
  double source_coverage = 0;    // fraction of valid source patches used at the end
};

// A match in an exemplar's own pixels.
struct ExemplarMatch {
  int exemplar = 0;  // 0 = `style`, k = exemplars[k - 1]
  float x = 0, y = 0;
};

struct SynthesisResult {
  Image image;          // B'
  OffsetField field;    // final match per target pixel, in `layout`'s atlas
  SourceLayout layout;  // the finest level's atlas of the exemplars
  std::vector<LevelStats> levels;  // coarsest first
  double seconds = 0;
  double source_coverage = 0;  // fraction of source patches used at the finest level
  int guide_channels = 0;        // guide channels matched (after compression)
  double kept_guide_variance = 1;

  ExemplarMatch match(int x, int y) const;
};

// Called after every search and vote with the overall progress in [0, 1];
// returning false cancels the run (CancelledError).
using ProgressCallback = std::function<bool(double)>;

SynthesisResult synthesize(const SynthesisInput& input, const SynthesisOptions& options,
                           const ProgressCallback& progress = {});

// A warm start along a shot (issue 32): the finest level alone, started from
// the previous frame's final field advected along the target's V- (pixels,
// x right, y down; Solver::advect), instead of coarse to fine from a cold
// start. `previous_field` is the finest level's size. Where `visible` (χ-:
// 1 channel, 1 = visible in the previous frame; empty = everywhere) is
// below 0.5 the pixel starts afresh instead, matched on the guides alone as
// a cold start's coarsest level is: its advected match belongs to what hid
// it. The finest level runs the options' iterations for level 0. Reported
// like synthesize(), with one level.
SynthesisResult synthesize_warm(const SynthesisInput& input, const SynthesisOptions& options,
                                const OffsetField& previous_field, const ImageView& velocity_backward,
                                const ImageView& visible = {}, const ProgressCallback& progress = {});

}  // namespace tempera

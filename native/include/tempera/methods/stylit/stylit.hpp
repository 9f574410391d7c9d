#pragma once
// StyLit per frame (Fišer et al. 2016, thesis ch. 8) as a method on top of the
// synthesis engine: the light-path guides of the exemplar render and of the
// target frame (tone-mapped the same way) steer where the painting's patches
// go. Optional temporal coherence in the manner of Fišer 2017 / EbSynth: one
// more guide pairs the painting itself with the previous stylized frame
// advected along the motion, so patches that fit what was painted there before
// win, except where the surface was just disoccluded.
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "tempera/app/guide_cache.hpp"
#include "tempera/app/light_path_guides.hpp"
#include "tempera/engine/image.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/engine/synthesis.hpp"

namespace tempera {

enum class Quality { Final, Preview };
template <>
struct EnumNames<Quality> {
  static constexpr const char* what = "quality";
  static constexpr std::array<const char*, 2> names = {"final", "preview"};
};

// Whether frames after the first start from the previous frame's matches
// (synthesize_warm). auto, the default: with the temporal guide (temporal
// weight > 0). Measured against cold frames (docs/benchmarks.md, issue 32,
// step 6): on a shot made by others, 3.3x faster, energy -0.7%, flicker -8%,
// detail +1.4%; on the demo, 3.5x, energy +1.8%, flicker -28%, detail -3.3%.
// on: also without the guide (the frames' boil goes, energy +3.5%). off:
// every frame coarse to fine.
enum class WarmStart { Auto, On, Off };
template <>
struct EnumNames<WarmStart> {
  static constexpr const char* what = "warm start";
  static constexpr std::array<const char*, 3> names = {"auto", "on", "off"};
};

struct StylitOptions {
  // Light-path guide weights in matching order; a weight <= 0 leaves the guide out.
  GuideWeights weights = default_guide_weights();
  // Pull towards the advected previous frame; 0 = frames independent, so a
  // farm can split the shot anywhere. The panel starts artists at 0.5
  // (settings.PANEL_TEMPORAL_WEIGHT).
  float temporal_weight = 0.0f;
  Quality quality = Quality::Final;
  // Frames after the first start from the previous frame's matches advected
  // along the motion and solve the finest level alone (synthesize_warm):
  // needs the previous frame's field (TemporalInput::previous_field).
  WarmStart warm_start = WarmStart::Auto;
  // Engine options. usage, patch_size, seed, threads (and anything else) are
  // taken as they are, except that the quality preset sets the iteration counts.
  SynthesisOptions synthesis;
};

// StyLit's own options besides the guide weights (--weights, a list) and the
// engine's (synthesis_option_table): the flags, help and ranges of `tempera
// stylize`, the Python defaults and the panel's tooltips come from here. The
// panel starts artists at a temporal weight of 0.5 (settings.PANEL_TEMPORAL_WEIGHT).
inline const auto& stylit_option_table() {
  using S = StylitOptions;
  static const auto table = std::make_tuple(
      field(&S::temporal_weight, "temporal_weight", "temporal",
            "pull of the previous stylized frame, moved along the rendered motion: higher values flicker less but "
            "let the paint stick and smear; 0 stylizes each frame on its own (0.5 typical)",
            0.0),
      field(&S::quality, "quality", "quality",
            "solver effort per frame: preview is about 5x faster, for trying settings"),
      field(&S::warm_start, "warm_start", "warm-start",
            "frames after the first start from the previous frame's matches moved along the rendered motion and "
            "solve only at full size, about 3.3x faster and steadier: auto does so with the temporal guide, "
            "on also without it (less boil; chains the frames), off never (each frame coarse to fine)"));
  return table;
}

// active_guides of the options' weights, and ValueError for a temporal
// weight that is negative or not finite.
std::vector<std::pair<std::string, float>> active_guides(const StylitOptions& options);

// Whether `options` warm-start frames after the first (WarmStart).
bool warm_starts(const StylitOptions& options);

// The engine options for `options`: `synthesis` with the quality preset applied.
SynthesisOptions engine_options(const StylitOptions& options);

// What the temporal guide needs from the previous frame.
struct TemporalInput {
  ImageView previous;            // previous stylized frame: target size, style channels
  ImageView velocity_backward;   // target's V-: 2 channels, pixels (x right, y down)
  ImageView occlusion_backward;  // target's χ-: 1 channel, 1 = visible in the previous frame
  // The previous frame's final matches (SynthesisResult::field), for a warm
  // start; null: a cold start.
  const OffsetField* previous_field = nullptr;
};

// One stylized frame. `style` is the painting, the size of the exemplar's
// guides. `temporal` may be null (first frame, or temporal_weight 0 without
// a warm start); `previous` is only read for a temporal weight > 0, and
// `previous_field` only when warm_starts(options).
// The result carries the engine's statistics (seconds, source coverage, ...).
SynthesisResult stylize_frame(const ImageView& style, const GuideFrame& exemplar, const GuideFrame& target,
                              const TemporalInput* temporal, const StylitOptions& options,
                              const ProgressCallback& progress = {});

// Mean absolute colour change along valid motion between two stylized frames:
// current(p) against previous(p - V-(p)) over the pixels with visible(p) != 0,
// all channels (0 if no pixel is visible). The figure of tempera.engine.temporal.flicker.
double flicker(const ImageView& previous, const ImageView& current, const ImageView& velocity_backward,
               const ImageView& visible);

}  // namespace tempera

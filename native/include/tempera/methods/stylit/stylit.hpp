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
#include "tempera/engine/image.hpp"
#include "tempera/engine/synthesis.hpp"

namespace tempera {

// The light-path guides StyLit matches (thesis fig. 8.4): the one table of
// their names (as in the guide cache, docs/guide_cache.md), light path
// expressions, default weights and UI texts. The CLI, the Python package and
// the Blender panel take theirs from it.
struct LightPathGuide {
  const char* name;        // guide-cache name, e.g. "LDDE"
  const char* expression;  // Heckbert's light path expression, e.g. "L.*DDE"
  float weight;            // default weight; 0 = off by default
  const char* label;       // short UI label
  const char* help;        // what the guide does to the picture
};

inline const std::vector<LightPathGuide>& light_path_guides() {
  // LDE counts double because a painting's stroke density follows the direct
  // diffuse shading; L.*DDE counts half, at guide sample counts it is the
  // noisiest guide; LD{1,2}E is off by default (it needs a second render).
  static const std::vector<LightPathGuide> table = {
      {"FULL", "L.*E", 1.0f, "Full GI",
       "the whole render (all light paths): overall light and dark; 1 typical"},
      {"LDE", "LDE", 2.0f, "Direct Diffuse",
       "direct diffuse light: shading and cast shadows, where strokes gather; 2 typical"},
      {"LSE", "LSE", 1.0f, "Direct Specular", "direct specular light: highlights; 1 typical, 0 for matte media"},
      {"LDDE", "L.*DDE", 0.5f, "Diffuse Interreflection",
       "diffuse interreflections: colour bleeding and soft fill light; 0.5 typical (noisy at few samples)"},
      {"LD12E", "LD{1,2}E", 0.0f, "First Two Diffuse Bounces",
       "the first two diffuse bounces (needs a second guide render); 0 = off"},
  };
  return table;
}

// Linear radiance -> guide values in [0, 1): NaN and negatives to 0, +inf to
// 1e6, Reinhard x / (1 + x), then the sRGB encoding. The same numbers as
// tempera.methods.stylit.stylize.tonemap (computed in double, stored as float).
Image tonemap_guide(const ImageView& linear);

enum class Quality { Final, Preview };
Quality parse_quality(const std::string& name);  // "final" | "preview", else ValueError
const char* quality_name(Quality quality);

// (name, default weight) of every light-path guide, in table order.
inline std::vector<std::pair<std::string, float>> default_guide_weights() {
  std::vector<std::pair<std::string, float>> out;
  for (const auto& g : light_path_guides()) out.emplace_back(g.name, g.weight);
  return out;
}

// "FULL, LDE, ..." for messages.
std::string light_path_guide_names();

// Sets the weights named in "NAME=W,NAME=W" (the CLI's --weights); names not
// listed keep theirs. ValueError naming an unknown guide or a bad number.
void parse_guide_weights(const std::string& text, std::vector<std::pair<std::string, float>>& weights);

struct StylitOptions {
  // Light-path guide weights in matching order; a weight <= 0 leaves the guide out.
  std::vector<std::pair<std::string, float>> weights = default_guide_weights();
  // Pull towards the advected previous frame; 0 = frames independent, so a
  // farm can split the shot anywhere. The panel starts artists at 0.5
  // (settings.PANEL_TEMPORAL_WEIGHT).
  float temporal_weight = 0.0f;
  Quality quality = Quality::Final;
  // Engine options. usage, patch_size, seed, threads (and anything else) are
  // taken as they are, except that the quality preset sets the iteration counts.
  SynthesisOptions synthesis;
};

// Light-path guides with weight > 0, in order. ValueError for unknown names,
// duplicates, non-finite weights or when no guide is left.
std::vector<std::pair<std::string, float>> active_guides(const StylitOptions& options);

// The engine options for `options`: `synthesis` with the quality preset applied.
SynthesisOptions engine_options(const StylitOptions& options);

// What the temporal guide needs from the previous frame.
struct TemporalInput {
  ImageView previous;            // previous stylized frame: target size, style channels
  ImageView velocity_backward;   // target's V-: 2 channels, pixels (x right, y down)
  ImageView occlusion_backward;  // target's χ-: 1 channel, 1 = visible in the previous frame
};

// One stylized frame. `style` is the painting, the size of the exemplar's
// guides. `temporal` may be null (first frame, or temporal_weight 0).
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

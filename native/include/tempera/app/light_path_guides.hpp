#pragma once
// The light-path guides of the guide cache (thesis fig. 8.4): the one table
// of their names (as in the cache, docs/guide_cache.md), light path
// expressions, default weights and UI texts, with their weights and tone
// mapping. StyLit and the coherent method match by them, the noise pass
// guides its noise by them; the CLI, the Python package and the Blender
// panel take theirs from here.
#include <string>
#include <utility>
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

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

// (name, weight) per light-path guide; a weight <= 0 leaves the guide out.
using GuideWeights = std::vector<std::pair<std::string, float>>;

// (name, default weight) of every light-path guide, in table order.
inline GuideWeights default_guide_weights() {
  GuideWeights out;
  for (const auto& g : light_path_guides()) out.emplace_back(g.name, g.weight);
  return out;
}

// "FULL, LDE, ..." for messages.
std::string light_path_guide_names();

// Sets the weights named in "NAME=W,NAME=W" (the CLI's --weights); names not
// listed keep theirs. ValueError naming an unknown guide or a bad number.
void parse_guide_weights(const std::string& text, GuideWeights& weights);

// The guides with weight > 0, in order. ValueError for unknown names,
// duplicates, non-finite weights or when no guide is left.
GuideWeights active_guides(const GuideWeights& weights);
// The names of active_guides(weights), in order.
std::vector<std::string> active_guide_names(const GuideWeights& weights);

// Linear radiance -> guide values in [0, 1): NaN and negatives to 0, +inf to
// 1e6, Reinhard x / (1 + x), then the sRGB encoding. The same numbers as
// tempera.engine.guides.tonemap (computed in double, stored as float).
Image tonemap_guide(const ImageView& linear);

}  // namespace tempera

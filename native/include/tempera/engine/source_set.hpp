#pragma once
// The source set: every exemplar a synthesis may copy from (a painted style,
// painted keyframes, the frames of a video exemplar), each with its own
// guides, mask, orientation and segment labels. Inside the engine the
// exemplars of one pyramid level are stacked into one atlas, so the search
// addresses (exemplar, x, y) as one position and needs no special cases;
// memory is the exemplars' own pixels (narrower ones padded to the widest).
#include <utility>
#include <vector>

#include "tempera/engine/image.hpp"

namespace tempera {

struct Exemplar {
  ImageView style;                // A' (the same channel count for every exemplar)
  std::vector<ImageView> guides;  // A_g, one per guide layer, in the order of the target guides
  ImageView mask;                 // optional, 1 channel, > 0.5 = may be copied
  ImageView orientation;          // optional, 1 channel, radians
  ImageView segments;             // optional, 1 channel, integer labels >= 0
  // Frames of one video exemplar share a `sequence` id (>= 0) and are ordered
  // by `time`; the search then also tries each match one frame earlier and
  // later. -1: a still exemplar.
  int sequence = -1;
  int time = 0;
};

// One exemplar's rows in a level's atlas.
struct SourceRect {
  int y0 = 0, width = 0, height = 0;
};

// Where each exemplar lies in one level's atlas: stacked top to bottom,
// left-aligned, with no gap. A match never straddles two exemplars because
// patch centres keep a margin inside their own exemplar.
struct SourceLayout {
  int width = 0, height = 0;
  std::vector<SourceRect> rects;
  std::vector<int> row_source;  // atlas row -> exemplar index
  // Per exemplar: the next and previous frame of its video (-1 if none or of
  // another size).
  std::vector<int> next_frame, previous_frame;

  // sizes: (width, height) per exemplar; sequence/time as in Exemplar.
  static SourceLayout stack(const std::vector<std::pair<int, int>>& sizes, const std::vector<int>& sequence,
                            const std::vector<int>& time);
  int source_at(int atlas_y) const { return row_source[std::size_t(atlas_y)]; }
  // Clamps an atlas position of exemplar `s` to the centres `margin` pixels
  // inside it.
  void clamp(int s, int margin, float& x, float& y) const;
};

// The per-exemplar images of one level (in layout order) as one atlas image,
// zero in the padding.
Image stack_atlas(std::vector<Image>&& images, const SourceLayout& layout);

}  // namespace tempera

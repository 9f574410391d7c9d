#pragma once
// Stroke re-synthesis of the rigid-body method (Dvorožňák et al. 2017, §6
// (iv), optional in the paper): the drawn bodies' lines re-made by the
// synthesis engine from a stroke exemplar, guided by one grayscale
// stroke-position guide G = 1 - distance-to-ink / d_max (the method notes;
// the paper's text is cut off before saying how G is made).
//
// The stroke exemplar is an RGBA image of strokes on transparent paper (a
// brush pen, charcoal...); its own G comes from its ink the same way, so the
// engine puts the exemplar's stroke cores on the body's lines and its blank
// paper away from them: the line keeps its place and takes the exemplar's look.
#include <string>

#include "tempera/engine/image.hpp"
#include "tempera/engine/synthesis.hpp"  // ProgressCallback

namespace tempera {

// Alpha above which a pixel is ink, for the guide.
constexpr float kStrokeInk = 0.5f;

// G of an RGBA drawing: 1 on its ink, falling to 0 at d_max px from it (H x W x 1).
Image stroke_guide(const ImageView& rgba, float d_max);

// The RGBA drawing `drawing` (straight alpha) with its strokes re-made from
// the RGBA stroke `exemplar` by the engine on the stroke-position guide
// (weight 0: the exemplar's texture with no guide). Only the box around the
// ink, with a margin of d_max and a patch, is synthesized; the rest stays
// blank. ValueError for an exemplar that is not RGBA or has no ink;
// `progress` returning false cancels (CancelledError).
Image resynthesize_strokes(const ImageView& drawing, const ImageView& exemplar, float d_max, float weight,
                           std::uint64_t seed = 1, const ProgressCallback& progress = {});

// The project's stroke exemplar: arcs and loops of a blue-black brush pen
// `width` px wide, its pressure swelling along each stroke, with a dry-brush
// grain in the ink (RGBA, straight alpha, transparent paper), for the tests,
// the demo and users without a scan.
Image generated_stroke_exemplar(int size = 160, float width = 4.0f, std::uint64_t seed = 0);
constexpr float kGeneratedStrokeColour[3] = {0.12f, 0.17f, 0.48f};

// A stroke exemplar from a file: RGBA as it is; an image without alpha is
// read as dark ink on white paper (alpha = 1 - luminance).
Image read_stroke_exemplar(const std::string& path);

// The stroke exemplar `spec` names: "generated" (generated_stroke_exemplar)
// or an image file (FileNotFoundError naming it when it is missing).
constexpr const char* kGeneratedStrokes = "generated";
Image load_stroke_exemplar(const std::string& spec);

}  // namespace tempera

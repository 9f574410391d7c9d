#pragma once
// The project's own "hand-drawn" exemplar for the rigid-body method: a
// known generator D_gen of squash, stretch and bend drawn with a wobbly
// pencil, so that tests and the demo have an exact oracle (D_gen applied to
// the target's tracks). Also a 2D bouncing-ball simulation for source tracks
// that need no Blender.
//
// D_gen for a frame f (radius-normalized, at the object's centre), applied
// right to left:
//  - a bend: the outline curves against the motion, p_perp += b s p_par^2
//    (s = speed / radius, drag of the air);
//  - a stretch along the velocity by 1 + k s, area-preserving (1 / (1 + k s)
//    across), inside a window of +-6 frames around events (fading from +-4),
//    since artists exaggerate around key poses and leave flights rigid;
//  - a squash along the event's normal by 1 - a ramp, ramp = 1 - |f - e| / 4
//    over +-3 frames, about the contact point (-n), area-preserving;
//  - the contact translation that puts the drawing on the obstacle.
#include <array>
#include <cstdint>

#include "tempera/engine/image.hpp"
#include "tempera/engine/option_table.hpp"
#include "tempera/methods/rigid/quadratic_map.hpp"
#include "tempera/methods/rigid/rigid.hpp"

namespace tempera {

enum class ProxyShape { circle, box };
template <>
struct EnumNames<ProxyShape> {
  static constexpr const char* what = "proxy shape";
  static constexpr std::array<const char*, 2> names{"circle", "box"};
};

struct ExemplarStyle {
  double stretch = 0.6;     // k
  double squash = 0.3;      // a, the squash at the event frame
  int squash_frames = 3;    // the ramp's half width
  double bend = 0.25;       // b
  double wobble = 0.6;      // px, the pencil's wobble amplitude
  double line_width = 2.5;  // px
  ProxyShape shape = ProxyShape::circle;
  std::uint64_t seed = 1;   // the pencil's jitter, fresh every frame: mix(seed, frame)
};

inline const auto& exemplar_style_table() {
  using E = ExemplarStyle;
  static const auto table = std::make_tuple(
      field(&E::stretch, "stretch", "stretch", "stretch along the velocity per radius-per-frame of speed, k (0.6)", 0, 10),
      field(&E::squash, "squash", "squash", "squash along the normal at an event, a (0.3)", 0, 0.9),
      field(&E::squash_frames, "squash_frames", "squash-frames", "half width of the squash ramp in frames (3)", 0, 30),
      field(&E::bend, "bend", "bend", "bend against the motion per radius-per-frame of speed, b (0.25)", 0, 10),
      field(&E::wobble, "wobble", "wobble", "the pencil's wobble amplitude in px (0.6)", 0, 20),
      field(&E::line_width, "line_width", "line-width", "the pencil's line width in px (2.5)", 0.5, 50),
      field(&E::shape, "shape", "shape", "the proxy: circle or box"),
      field(&E::seed, "seed", "seed", "seed of the pencil's jitter (fresh every frame)"));
  return table;
}

// How strongly frame f of the track is stylized: (stretch window, squash ramp,
// nearest event index or -1).
struct EventInfluence {
  double stretch_window = 0;
  double squash_ramp = 0;
  int event = -1;
};
EventInfluence event_influence(const Track& track, int frame, int squash_frames);

QuadraticMap generator_map(const Track& track, int frame, const ExemplarStyle& style);

// The proxy's outline (px) at a frame: a circle, or the box's corners.
std::vector<Vec2> proxy_outline(const TrackFrame& f, ProxyShape shape, double inset_px = 0, int samples = 360);
// The proxy's filled silhouette (1 channel).
Image proxy_mask(const TrackFrame& f, ProxyShape shape, int width, int height);

// The generated drawing of frame f (RGBA, straight alpha, graphite ink).
Image draw_exemplar_frame(const Track& track, int frame, const ExemplarStyle& style, int width, int height);

// A ball thrown from `start` with `velocity` (px/frame), gravity g
// (px/frame^2, down the image), bouncing on the floor y = floor with
// restitution e, sampled over `frames` frames; events at the frames nearest
// to each bounce, contact on the floor, normal (0, -1).
Track bouncing_ball(Vec2 start, Vec2 velocity, double radius, double gravity, double floor, double restitution,
                    double spin, int frames);

}  // namespace tempera

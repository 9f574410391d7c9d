#include "tempera/methods/rigid/rigid_exemplar.hpp"

#include <algorithm>
#include <cmath>

#include "tempera/engine/error.hpp"
#include "tempera/engine/rng.hpp"
#include "tempera/methods/rigid/stroke_raster.hpp"

namespace tempera {

namespace {

constexpr double kPi = 3.14159265358979323846;

// M D + o: an affine map applied after D.
QuadraticMap affine_after(const std::array<double, 4>& M, Vec2 o, const QuadraticMap& D) {
  QuadraticMap out;
  for (int j = 0; j < 6; ++j) {
    out.at(0, j) = M[0] * D.at(0, j) + M[1] * D.at(1, j);
    out.at(1, j) = M[2] * D.at(0, j) + M[3] * D.at(1, j);
  }
  out.at(0, 5) += o.x, out.at(1, 5) += o.y;
  return out;
}

// R_phi diag(along, across) R_-phi.
std::array<double, 4> axis_scale(double phi, double along, double across) {
  const double c = std::cos(phi), s = std::sin(phi);
  return {c * c * along + s * s * across, c * s * (along - across), c * s * (along - across),
          s * s * along + c * c * across};
}

}  // namespace

EventInfluence event_influence(const Track& track, int frame, int squash_frames) {
  EventInfluence out;
  int best = 1 << 30;
  for (std::size_t i = 0; i < track.events.size(); ++i) {
    const int d = std::abs(frame - track.events[i].frame);
    if (d < best) best = d, out.event = int(i);
  }
  if (out.event < 0) return out;
  out.stretch_window = best <= 4 ? 1.0 : best >= 6 ? 0.0 : (6.0 - best) / 2.0;
  out.squash_ramp = std::max(0.0, 1.0 - double(best) / double(squash_frames + 1));
  return out;
}

QuadraticMap generator_map(const Track& track, int frame, const ExemplarStyle& style) {
  validate_fields(style, exemplar_style_table());
  if (frame < 0 || frame >= int(track.frames.size())) throw ValueError(concat("frame ", frame, " is outside the track"));
  const TrackFrame& f = track.frames[std::size_t(frame)];
  const EventInfluence inf = event_influence(track, frame, style.squash_frames);
  if (inf.event < 0) return QuadraticMap::identity();
  const double s = std::hypot(f.velocity.x, f.velocity.y) / f.radius * inf.stretch_window;
  // The bend in the motion's frame (x along v): the sides trail behind.
  QuadraticMap bend;
  bend.at(0, 3) = -style.bend * s;
  const double c = std::cos(f.delta), sn = std::sin(f.delta);
  QuadraticMap D = conjugated(bend, {c, -sn, sn, c});
  const double st = 1 + style.stretch * s;
  D = affine_after(axis_scale(f.delta, st, 1 / st), {0, 0}, D);
  const RigidEvent& e = track.events[std::size_t(inf.event)];
  const double phi = std::atan2(e.normal.y, e.normal.x);
  const double sq = 1 - style.squash * inf.squash_ramp;
  // Squash about the contact point a = -n: p -> a + S (p - a).
  const auto S = axis_scale(phi, sq, 1 / sq);
  const Vec2 a{-e.normal.x, -e.normal.y};
  const Vec2 o{a.x - (S[0] * a.x + S[1] * a.y), a.y - (S[2] * a.x + S[3] * a.y)};
  D = affine_after(S, o, D);
  // Onto the obstacle: close the gap between the proxy and the contact line.
  const double gap = ((f.centre.x - e.contact.x) * e.normal.x + (f.centre.y - e.contact.y) * e.normal.y - f.radius) / f.radius;
  const double t = -gap * inf.squash_ramp;
  return affine_after({1, 0, 0, 1}, {t * e.normal.x, t * e.normal.y}, D);
}

std::vector<Vec2> proxy_outline(const TrackFrame& f, ProxyShape shape, double inset_px, int samples) {
  const double r = f.radius - inset_px;
  std::vector<Vec2> out;
  for (int i = 0; i < samples; ++i) {
    const double t = 2 * kPi * i / samples;
    Vec2 u{std::cos(t), std::sin(t)};
    if (shape == ProxyShape::box) {  // the square inscribed in the radius, rotated by theta
      const double m = std::max(std::abs(std::cos(t - f.theta)), std::abs(std::sin(t - f.theta)));
      u = {u.x / (m * std::sqrt(2.0)), u.y / (m * std::sqrt(2.0))};
    }
    out.push_back({f.centre.x + r * u.x, f.centre.y + r * u.y});
  }
  return out;
}

Image proxy_mask(const TrackFrame& f, ProxyShape shape, int width, int height) {
  Image mask(width, height, 1);
  fill_polygon(mask, proxy_outline(f, shape, 0, 720));
  return mask;
}

Image draw_exemplar_frame(const Track& track, int frame, const ExemplarStyle& style, int width, int height) {
  const QuadraticMap D = generator_map(track, frame, style);
  const TrackFrame& f = track.frames[std::size_t(frame)];
  Rng rng(style.seed, std::uint64_t(frame));
  // The pencil: a wobble of a few random harmonics, a random start and a
  // short overshoot past it; fresh every frame, so the line boils.
  double amp[4], freq[4], phase[4];
  for (int j = 0; j < 4; ++j) amp[j] = rng.uniform(), freq[j] = 3 + rng.below(7), phase[j] = 2 * kPi * rng.uniform();
  const double start = 2 * kPi * rng.uniform(), overshoot = 0.25 + 0.2 * rng.uniform();
  const int samples = 480;
  const std::vector<Vec2> outline = proxy_outline(f, style.shape, style.line_width / 2, samples);
  std::vector<Vec2> stroke;
  const int total = int(samples * (1 + overshoot / (2 * kPi)));
  const int first = int(start / (2 * kPi) * samples);
  for (int i = 0; i <= total; ++i) {
    const Vec2 p = outline[std::size_t((first + i) % samples)];
    const double t = 2 * kPi * i / samples;
    double w = 0;
    for (int j = 0; j < 4; ++j) w += amp[j] * std::sin(freq[j] * t + phase[j]);
    w *= style.wobble / 2;
    // The overshoot drifts outward, as a quick pencil does.
    if (i > samples) w += 1.5 * double(i - samples) / double(total - samples);
    Vec2 u{(p.x - f.centre.x) / f.radius, (p.y - f.centre.y) / f.radius};
    const double len = std::hypot(u.x, u.y);
    u = {u.x * (1 + w / f.radius / len), u.y * (1 + w / f.radius / len)};
    const Vec2 q = apply(D, u);
    stroke.push_back({f.centre.x + f.radius * q.x, f.centre.y + f.radius * q.y});
  }
  Image ink(width, height, 1);
  draw_stroke(ink, stroke, style.line_width, false);
  Image out(width, height, 4);
  for (std::size_t i = 0; i < ink.pixel_count(); ++i) {
    float* o = out.data() + 4 * i;
    o[0] = 0.16f, o[1] = 0.16f, o[2] = 0.2f, o[3] = ink.data()[i];
  }
  return out;
}

Track bouncing_ball(Vec2 start, Vec2 velocity, double radius, double gravity, double floor, double restitution,
                    double spin, int frames) {
  if (frames < 3 || radius <= 0) throw ValueError("bouncing_ball needs >= 3 frames and a positive radius");
  constexpr int steps = 64;  // sub-steps per frame
  Track track;
  Vec2 p = start, v = velocity;
  std::vector<Vec2> centres;
  std::vector<double> bounces;
  for (int f = 0; f < frames + 1; ++f) {
    centres.push_back(p);
    for (int k = 0; k < steps; ++k) {
      const double dt = 1.0 / steps;
      v.y += gravity * dt;
      p.x += v.x * dt, p.y += v.y * dt;
      if (p.y + radius > floor && v.y > 0) {
        p.y = floor - radius;
        // Too slow to bounce visibly: it rolls, no event.
        if (v.y > 0.5) bounces.push_back(f + double(k + 1) / steps);
        v.y = v.y > 0.5 ? -restitution * v.y : 0;
      }
    }
  }
  for (int f = 0; f < frames; ++f) {
    TrackFrame tf;
    tf.centre = centres[std::size_t(f)];
    const Vec2 prev = centres[std::size_t(std::max(0, f - 1))], next = centres[std::size_t(f + 1)];
    tf.velocity = {(next.x - prev.x) / (f > 0 ? 2 : 1), (next.y - prev.y) / (f > 0 ? 2 : 1)};
    tf.theta = spin * f;
    tf.radius = radius;
    track.frames.push_back(tf);
  }
  for (const double b : bounces) {
    const int f = int(std::lround(b));
    if (f >= frames || (!track.events.empty() && track.events.back().frame == f)) continue;
    track.events.push_back({f, {track.frames[std::size_t(f)].centre.x, floor}, {0, -1}});
  }
  derive_trajectory_angles(track);
  return track;
}

}  // namespace tempera

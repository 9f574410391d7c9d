#include "tempera/methods/rigid/rigid.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "tempera/engine/error.hpp"

namespace tempera {

namespace {

constexpr double kPi = 3.14159265358979323846;

double wrap(double a) { return std::remainder(a, 2 * kPi); }
double speed(const TrackFrame& f) { return std::hypot(f.velocity.x, f.velocity.y); }

}  // namespace

std::array<double, 4> augmentation_matrix(const Augmentation& a) {
  const double c = std::cos(a.gamma), s = std::sin(a.gamma), f = a.flip ? -1 : 1;
  return {c * f, -s, s * f, c};  // R_gamma diag(f, 1)
}

void validate_track(const Track& track) {
  const auto limit = std::int64_t(kMaxTrackPixels);  // printed whole
  if (track.frames.empty()) throw ValueError("a track needs at least one frame");
  const auto within = [](double v) { return std::isfinite(v) && std::abs(v) <= kMaxTrackPixels; };
  const auto check = [&](Vec2 v, const char* what, std::size_t f) {
    if (!within(v.x) || !within(v.y))
      throw ValueError(concat("frame ", f, ": the ", what, " (", v.x, ", ", v.y, ") must be finite and within ",
                              limit, " pixels"));
  };
  for (std::size_t f = 0; f < track.frames.size(); ++f) {
    const TrackFrame& t = track.frames[f];
    check(t.centre, "centre", f);
    check(t.velocity, "velocity", f);
    if (!within(t.theta))
      throw ValueError(concat("frame ", f, ": the rotation ", t.theta, " must be finite and within ", limit));
    if (!(t.radius > 0 && t.radius <= kMaxTrackPixels))
      throw ValueError(concat("frame ", f, ": the radius ", t.radius, " must be > 0 and at most ", limit,
                              " pixels"));
  }
  for (const RigidEvent& e : track.events) {
    if (e.frame < 0 || e.frame >= int(track.frames.size()))
      throw ValueError(concat("an event at frame ", e.frame, " is outside the track's ", track.frames.size(),
                              " frames"));
    check(e.contact, "event's contact", std::size_t(e.frame));
    if (!within(e.normal.x) || !within(e.normal.y) || (e.normal.x == 0 && e.normal.y == 0))
      throw ValueError(concat("frame ", e.frame, ": the event's normal must be finite and not zero"));
  }
}

void derive_trajectory_angles(Track& track, double rest_speed) {
  double delta = 0;
  for (TrackFrame& f : track.frames) {
    if (speed(f) > rest_speed) delta = std::atan2(f.velocity.y, f.velocity.x);
    f.delta = delta;
    f.alpha = wrap(f.theta - delta);
  }
}

std::vector<SubSequence> cut_subsequences(const Track& track) {
  const int n = int(track.frames.size());
  if (n == 0) throw ValueError("a track needs at least one frame");
  std::vector<SubSequence> out;
  if (track.events.empty()) return {SubSequence{-1, n / 2, 0, n - 1}};
  for (std::size_t i = 0; i < track.events.size(); ++i) {
    const int e = track.events[i].frame;
    if (e < 0 || e >= n) throw ValueError(concat("event frame ", e, " is outside the track's ", n, " frames"));
    if (i > 0 && e <= track.events[i - 1].frame) throw ValueError("events must be sorted by frame, one per frame");
    SubSequence s{int(i), e, 0, n - 1};
    if (i > 0) {
      const int prev = track.events[i - 1].frame, gap = e - prev;
      s.first = std::max(0, (prev + e) / 2 - std::min(8, gap / 4) / 2);
    }
    if (i + 1 < track.events.size()) {
      const int next = track.events[i + 1].frame, gap = next - e;
      s.last = std::min(n - 1, (e + next) / 2 + (std::min(8, gap / 4) + 1) / 2);
    }
    out.push_back(s);
  }
  return out;
}

double angle_difference(double a, double b, int order) {
  const double period = 2 * kPi / std::max(1, order);
  return std::remainder(a - b, period);
}

TrackFrame augmented(const TrackFrame& f, const Augmentation& a) {
  const auto L = augmentation_matrix(a);
  TrackFrame out = f;
  out.velocity = {a.rho * (L[0] * f.velocity.x + L[1] * f.velocity.y), a.rho * (L[2] * f.velocity.x + L[3] * f.velocity.y)};
  const double mirror = a.flip ? -1 : 1;
  out.theta = wrap((a.flip ? kPi - f.theta : f.theta) + a.gamma);
  out.delta = wrap((a.flip ? kPi - f.delta : f.delta) + a.gamma);
  out.alpha = wrap(mirror * f.alpha);
  return out;
}

namespace {

// Frames of s and t paired by their offset from the key frame.
template <class Fn>
int for_common_frames(const SubSequence& s, const SubSequence& t, Fn&& fn) {
  const int before = std::min(s.centre - s.first, t.centre - t.first);
  const int after = std::min(s.last - s.centre, t.last - t.centre);
  for (int k = -before; k <= after; ++k) fn(s.centre + k, t.centre + k);
  return before + after + 1;
}

}  // namespace

double sub_sequence_diff(const Track& source, const SubSequence& s, const Augmentation& a, const Track& target,
                         const SubSequence& t, const RigidOptions& options, double lambda_vel) {
  double vel = 0, dir = 0, rot = 0;
  const int n = for_common_frames(s, t, [&](int fs, int ft) {
    const TrackFrame S = augmented(source.frames[std::size_t(fs)], a);
    const TrackFrame& T = target.frames[std::size_t(ft)];
    vel += std::pow(S.velocity.x - T.velocity.x, 2) + std::pow(S.velocity.y - T.velocity.y, 2);
    dir += std::pow(angle_difference(S.delta, T.delta), 2);
    if (options.symmetry > 0) rot += std::pow(angle_difference(S.alpha, T.alpha, options.symmetry), 2);
  });
  return (lambda_vel * vel + options.lambda_dir * dir + options.lambda_rot * rot) / n;
}

namespace {

double resolved_lambda_vel(const Track& target, const RigidOptions& options) {
  if (options.lambda_vel > 0) return options.lambda_vel;
  std::vector<double> speeds;
  for (const TrackFrame& f : target.frames) speeds.push_back(speed(f));
  std::nth_element(speeds.begin(), speeds.begin() + long(speeds.size() / 2), speeds.end());
  const double median = std::max(speeds[speeds.size() / 2], 1e-3);
  return 1 / (median * median);
}

double normal_angle(const Track& track, const SubSequence& s) {
  if (s.event < 0) return std::atan2(-1.0, 0.0);
  const Vec2 n = track.events[std::size_t(s.event)].normal;
  return std::atan2(n.y, n.x);
}

// The augmentations tried for a source sub-sequence against a target one.
std::vector<Augmentation> augmentations(const Track& source, const SubSequence& s, const Track& target,
                                        const SubSequence& t, const RigidOptions& options) {
  if (!options.augment) return {Augmentation{}};
  std::vector<Augmentation> out;
  const double target_normal = normal_angle(target, t), source_normal = normal_angle(source, s);
  for (int flip = 0; flip <= (options.flip ? 1 : 0); ++flip) {
    // The flip mirrors the normal's angle about the vertical: phi -> pi - phi.
    const double mirrored = flip ? kPi - source_normal : source_normal;
    std::vector<double> gammas{0.0};
    const double turn = wrap(target_normal - mirrored);
    if (std::abs(turn) > 1e-9) gammas.push_back(turn);
    for (const double gamma : gammas)
      for (int i = 0; i < options.scales; ++i) {
        const double rho = options.scales == 1 ? 1.0 : 0.2 + 0.8 * i / (options.scales - 1);
        out.push_back({gamma, rho, bool(flip)});
      }
  }
  return out;
}

struct Match {
  int exemplar = 0;
  SubSequence sub;
  Augmentation augmentation;
  double diff = 0;
};

// D_hat of one target frame from its sub-sequence's matches, with the
// matched residuals weighted by `share`.
RigidFrame frame_from_matches(const std::vector<RigidExemplar>& exemplars, const std::vector<Match>& matches,
                              const SubSequence& t, int frame, const Track& target, const RigidOptions& options) {
  std::vector<double> weights;
  for (const Match& m : matches) weights.push_back(1 / (m.diff + 1e-12));
  const double total = std::accumulate(weights.begin(), weights.end(), 0.0);
  RigidFrame out;
  std::vector<QuadraticMap> maps;
  double xi = 0;
  for (std::size_t k = 0; k < matches.size(); ++k) {
    const Match& m = matches[k];
    const RigidExemplar& ex = exemplars[std::size_t(m.exemplar)];
    const int wanted = m.sub.centre + frame - t.centre;
    const int fs = std::clamp(wanted, m.sub.first, m.sub.last);
    const double fade = std::max(0.0, 1.0 - std::abs(wanted - fs) / 2.0);
    maps.push_back(damped(conjugated(ex.maps[std::size_t(fs)], augmentation_matrix(m.augmentation)), fade));
    weights[k] /= total;
    out.residuals.push_back({m.exemplar, fs, m.augmentation, weights[k]});
    double vs = 0, vt = 0;
    for_common_frames(m.sub, t, [&](int a, int b) {
      vs += m.augmentation.rho * speed(ex.track.frames[std::size_t(a)]);
      vt += speed(target.frames[std::size_t(b)]);
    });
    xi += weights[k] * std::clamp(vt > 0 ? vs / vt : 1.0, 0.0, 1.0);
  }
  out.D = blend(maps, weights);
  out.xi = options.damp ? xi : 1.0;
  out.D = damped(out.D, out.xi);
  return out;
}

void validate(const std::vector<RigidExemplar>& exemplars, const Track& target) {
  if (exemplars.empty()) throw ValueError("the rigid method needs at least one exemplar");
  for (std::size_t i = 0; i < exemplars.size(); ++i)
    if (exemplars[i].maps.size() != exemplars[i].track.frames.size() || exemplars[i].maps.empty())
      throw ValueError(concat("exemplar ", i, " has ", exemplars[i].maps.size(), " fitted maps for ",
                              exemplars[i].track.frames.size(), " track frames"));
  if (target.frames.empty()) throw ValueError("the target track has no frames");
}

}  // namespace

std::vector<RigidFrame> synthesize_deformations(const std::vector<RigidExemplar>& exemplars, const Track& target,
                                                const RigidOptions& options) {
  validate(exemplars, target);
  validate_fields(options, rigid_option_table());
  const double lambda_vel = resolved_lambda_vel(target, options);
  const std::vector<SubSequence> target_subs = cut_subsequences(target);
  // Per target sub-sequence, its K nearest augmented sources.
  std::vector<std::vector<Match>> nearest;
  for (const SubSequence& t : target_subs) {
    std::vector<Match> all;
    for (std::size_t e = 0; e < exemplars.size(); ++e)
      for (const SubSequence& s : cut_subsequences(exemplars[e].track))
        for (const Augmentation& a : augmentations(exemplars[e].track, s, target, t, options))
          all.push_back({int(e), s, a, sub_sequence_diff(exemplars[e].track, s, a, target, t, options, lambda_vel)});
    const std::size_t k = std::min<std::size_t>(std::size_t(options.k), all.size());
    std::partial_sort(all.begin(), all.begin() + long(k), all.end(),
                      [](const Match& a, const Match& b) { return a.diff < b.diff; });
    all.resize(k);
    nearest.push_back(all);
  }
  std::vector<RigidFrame> out(target.frames.size());
  for (int f = 0; f < int(target.frames.size()); ++f) {
    // The sub-sequences holding f: one, or two in an overlap.
    std::vector<std::size_t> holders;
    for (std::size_t i = 0; i < target_subs.size(); ++i)
      if (f >= target_subs[i].first && f <= target_subs[i].last) holders.push_back(i);
    double beta = 0;  // the next sub-sequence's share in an overlap
    if (holders.size() > 1) {
      const SubSequence& next = target_subs[holders[1]];
      beta = double(f - next.first + 1) / double(target_subs[holders[0]].last - next.first + 2);
      if (!options.overlap_blend) holders.erase(holders.begin() + (beta < 0.5 ? 1 : 0));
    }
    RigidFrame a = frame_from_matches(exemplars, nearest[holders[0]], target_subs[holders[0]], f, target, options);
    if (holders.size() > 1) {
      const SubSequence& next = target_subs[holders[1]];
      const RigidFrame b = frame_from_matches(exemplars, nearest[holders[1]], next, f, target, options);
      a.D = blend({a.D, b.D}, {1 - beta, beta});
      a.xi = (1 - beta) * a.xi + beta * b.xi;
      for (ResidualRef& r : a.residuals) r.weight *= 1 - beta;
      for (ResidualRef r : b.residuals) {
        r.weight *= beta;
        // The same residual from both sides counts once.
        const auto same = std::find_if(a.residuals.begin(), a.residuals.end(), [&](const ResidualRef& q) {
          return q.exemplar == r.exemplar && q.frame == r.frame && q.augmentation.gamma == r.augmentation.gamma &&
                 q.augmentation.rho == r.augmentation.rho && q.augmentation.flip == r.augmentation.flip;
        });
        if (same != a.residuals.end()) same->weight += r.weight;
        else a.residuals.push_back(r);
      }
    }
    a.D = fold_guarded(a.D, 1.25, options.fold_min_det);
    out[std::size_t(f)] = a;
  }
  return out;
}

}  // namespace tempera

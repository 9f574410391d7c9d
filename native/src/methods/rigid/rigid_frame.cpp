#include "tempera/methods/rigid/rigid_frame.hpp"

#include <algorithm>
#include <cmath>

#include "tempera/engine/distance_transform.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/engine/patch_distance.hpp"
#include "tempera/methods/rigid/silhouette.hpp"

namespace tempera {

namespace {

// image sampled at (x, y), 0 outside it (a drawing ends at its frame).
void sample_or_zero(const ImageView& image, double x, double y, float* out) {
  if (x < -0.5 || y < -0.5 || x > image.width - 0.5 || y > image.height - 0.5) {
    std::fill_n(out, image.channels, 0.0f);
    return;
  }
  sample_bilinear(image.data, image.width, image.height, image.channels, image.channels, float(x), float(y), out);
}

// Pixels within `reach` radii of the centre, clipped to the image.
template <class Fn>
void for_box(int width, int height, Vec2 centre, double reach, Fn&& fn) {
  const int x0 = std::max(0, int(std::floor(centre.x - reach))), x1 = std::min(width - 1, int(std::ceil(centre.x + reach)));
  const int y0 = std::max(0, int(std::floor(centre.y - reach))), y1 = std::min(height - 1, int(std::ceil(centre.y + reach)));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) fn(x, y);
}

constexpr double kReach = 3.0;  // radii around the centre a deformed drawing may reach

}  // namespace

Image extract_residual(const ImageView& drawing, const QuadraticMap& D, ObjectFrame frame) {
  require_nonempty(drawing, "drawing");
  Image out(drawing.width, drawing.height, drawing.channels);
  for (int y = 0; y < drawing.height; ++y)
    for (int x = 0; x < drawing.width; ++x) {
      const Vec2 q = apply(D, {(x - frame.centre.x) / frame.radius, (y - frame.centre.y) / frame.radius});
      sample_or_zero(drawing, frame.centre.x + frame.radius * q.x, frame.centre.y + frame.radius * q.y, out.pixel(x, y));
    }
  return out;
}

Image apply_map(const ImageView& residual, const QuadraticMap& D, ObjectFrame frame) {
  require_nonempty(residual, "residual");
  Image out(residual.width, residual.height, residual.channels);
  for_box(residual.width, residual.height, frame.centre, kReach * frame.radius, [&](int x, int y) {
    bool ok = false;
    const Vec2 u = inverse_apply(D, {(x - frame.centre.x) / frame.radius, (y - frame.centre.y) / frame.radius}, &ok);
    if (ok) sample_or_zero(residual, frame.centre.x + frame.radius * u.x, frame.centre.y + frame.radius * u.y, out.pixel(x, y));
  });
  return out;
}

namespace {

// Residual k carried to the target pose and deformed by D_hat: for a target
// pixel, u_T = D_hat^-1((p - c_T) / r_T), turned back by the rotation
// theta^T - theta'^S and the augmentation L, then c_S + r_S u_S.
Image warp_match(const ImageView& residual, const TrackFrame& source, const ResidualRef& ref, const TrackFrame& target,
                 const QuadraticMap& D, int width, int height, Vec2 shift) {
  const auto L = augmentation_matrix(ref.augmentation);
  const double det = L[0] * L[3] - L[1] * L[2];
  const double turn = target.theta - augmented(source, ref.augmentation).theta;
  const double c = std::cos(-turn), s = std::sin(-turn);
  const Vec2 centre{target.centre.x + shift.x, target.centre.y + shift.y};
  Image out(width, height, residual.channels);
  for_box(width, height, centre, kReach * target.radius, [&](int x, int y) {
    bool ok = false;
    const Vec2 u = inverse_apply(D, {(x - centre.x) / target.radius, (y - centre.y) / target.radius}, &ok);
    if (!ok) return;
    const Vec2 r{c * u.x - s * u.y, s * u.x + c * u.y};
    const Vec2 us{(L[3] * r.x - L[1] * r.y) / det, (-L[2] * r.x + L[0] * r.y) / det};
    sample_or_zero(residual, source.centre.x + source.radius * us.x, source.centre.y + source.radius * us.y,
                   out.pixel(x, y));
  });
  return out;
}

Image alpha_of(const Image& rgba) {
  Image a(rgba.width(), rgba.height(), 1);
  for (std::size_t i = 0; i < a.pixel_count(); ++i) a.data()[i] = rgba.data()[4 * i + 3];
  return a;
}

// The stand-in for the n-way morph of the warped matches (see the header).
Image merge(const std::vector<Image>& warped, const std::vector<double>& weights) {
  if (warped.size() == 1) return warped[0];
  const int w = warped[0].width(), h = warped[0].height();
  const float d_max = 8;
  Image mean_distance(w, h, 1), colour(w, h, 3), colour_weight(w, h, 1);
  for (std::size_t k = 0; k < warped.size(); ++k) {
    const Image a = alpha_of(warped[k]);
    Image ink(w, h, 1);
    for (std::size_t i = 0; i < ink.pixel_count(); ++i) ink.data()[i] = a.data()[i] > 0.5f ? 1.0f : 0.0f;
    const Image d = line_distance(ink.view(), d_max);
    for (std::size_t i = 0; i < d.pixel_count(); ++i) {
      mean_distance.data()[i] += float(weights[k]) * d.data()[i] * d_max;
      const float ak = a.data()[i] * float(weights[k]);
      for (int ch = 0; ch < 3; ++ch) colour.data()[3 * i + std::size_t(ch)] += ak * warped[k].data()[4 * i + std::size_t(ch)];
      colour_weight.data()[i] += ak;
    }
  }
  // Ink colour where no match has ink: the overall mean.
  double mean[3] = {0, 0, 0}, total = 0;
  for (std::size_t i = 0; i < colour_weight.pixel_count(); ++i) {
    for (int ch = 0; ch < 3; ++ch) mean[ch] += colour.data()[3 * i + std::size_t(ch)];
    total += colour_weight.data()[i];
  }
  Image out(w, h, 4);
  for (std::size_t i = 0; i < out.pixel_count(); ++i) {
    // Ink where the matches' strokes agree to within a pixel on average.
    const double a = std::clamp(1.0 - double(mean_distance.data()[i]), 0.0, 1.0);
    out.data()[4 * i + 3] = float(a);
    const float cw = colour_weight.data()[i];
    for (int ch = 0; ch < 3; ++ch)
      out.data()[4 * i + std::size_t(ch)] = cw > 1e-4f ? colour.data()[3 * i + std::size_t(ch)] / cw
                                                       : float(total > 0 ? mean[ch] / total : 0);
  }
  return out;
}

}  // namespace

Image render_rigid_frame(const std::vector<RigidExemplar>& exemplars, const ResidualSource& residuals,
                         const Track& target, int frame, const RigidFrame& deformation, int width, int height,
                         Vec2 shift) {
  if (frame < 0 || frame >= int(target.frames.size())) throw ValueError(concat("target frame ", frame, " out of range"));
  if (width <= 0 || height <= 0) throw ValueError("the output frame must have a positive size");
  std::vector<Image> warped;
  std::vector<double> weights;
  for (const ResidualRef& ref : deformation.residuals) {
    if (ref.weight <= 1e-6) continue;
    const ImageView residual = residuals(ref.exemplar, ref.frame);
    if (residual.channels != 4) throw ValueError(concat("residual ", ref.exemplar, "/", ref.frame, " must be RGBA"));
    const TrackFrame& source = exemplars[std::size_t(ref.exemplar)].track.frames[std::size_t(ref.frame)];
    warped.push_back(warp_match(residual, source, ref, target.frames[std::size_t(frame)], deformation.D, width, height, shift));
    weights.push_back(ref.weight);
  }
  if (warped.empty()) return Image(width, height, 4);
  double total = 0;
  for (double w : weights) total += w;
  for (double& w : weights) w /= total;
  return merge(warped, weights);
}

double contact_gap(const ImageView& rgba, const RigidEvent& event) {
  if (rgba.channels != 4) throw ValueError("contact_gap needs an RGBA frame");
  Image alpha(rgba.width, rgba.height, 1);
  for (std::size_t i = 0; i < alpha.pixel_count(); ++i) alpha.data()[i] = rgba.data[4 * i + 3];
  const std::vector<Vec2> outline = iso_points(alpha.view(), 0.5f);
  if (outline.empty()) throw ValueError("contact_gap: the frame has no ink");
  double gap = 1e300;
  for (const Vec2& p : outline)
    gap = std::min(gap, (p.x - event.contact.x) * event.normal.x + (p.y - event.contact.y) * event.normal.y);
  return gap;
}

std::vector<Vec2> contact_shifts(const std::vector<RigidExemplar>& exemplars, const ResidualSource& residuals,
                                 const Track& target, const std::vector<RigidFrame>& deformations, int width,
                                 int height, int fade) {
  std::vector<Vec2> shifts(target.frames.size());
  for (const RigidEvent& e : target.events) {
    const Image at_event = render_rigid_frame(exemplars, residuals, target, e.frame, deformations[std::size_t(e.frame)],
                                              width, height);
    double gap = 0;
    try {
      gap = contact_gap(at_event.view(), e);
    } catch (const ValueError&) {
      continue;  // nothing drawn at the event (off screen): nothing to fix
    }
    for (int f = std::max(0, e.frame - fade); f <= std::min(int(target.frames.size()) - 1, e.frame + fade); ++f) {
      const double ramp = 1 - double(std::abs(f - e.frame)) / double(fade + 1);
      shifts[std::size_t(f)].x -= ramp * gap * e.normal.x;
      shifts[std::size_t(f)].y -= ramp * gap * e.normal.y;
    }
  }
  return shifts;
}

}  // namespace tempera

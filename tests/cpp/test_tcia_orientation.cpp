// Bénard et al. 2013 (TCIA), §3.1-3.2: with orientation fields, the coherent
// method compares patches rotated by the smallest angle between the frame's
// and the exemplar's orientation, so hatching follows the frame's field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tempera/engine/orientation.hpp"
#include "tempera/methods/tcia/tcia.hpp"
#include "tcia_measures.hpp"

using namespace tempera;

namespace {

constexpr float kPi = 3.14159265f;

// Horizontal hatching (edge direction 0) on a flat shading: a directional
// exemplar. The shot is a disc of paper turning about the picture's centre,
// `degrees` per frame, whose orientation field turns with it, and whose
// shading is flat too: only the orientation says which way to hatch.
struct TurningHatching {
  static constexpr int size = 40;
  static constexpr float centre = 19.5f;
  Image style, style_guide, style_angle;
  std::vector<Image> guides, angle, v_minus, v_plus, chi;
  std::vector<float> truth;  // the field's angle per frame
  Shot shot;

  TurningHatching(int frames, float degrees, float start_degrees) {
    style = Image(48, 48, 3), style_guide = Image(48, 48, 1, 0.5f), style_angle = Image(48, 48, 1, 0.0f);
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 48; ++x)
        for (int c = 0; c < 3; ++c) style.at(x, y, c) = 0.5f + 0.5f * std::cos(2 * kPi * y / 6.0f);
    const float step = degrees * kPi / 180;
    for (int t = 0; t < frames; ++t) {
      const float a = start_degrees * kPi / 180 + step * t;
      truth.push_back(std::fmod(a, kPi));
      Image vm(size, size, 2), vp(size, size, 2);
      for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
          const float dx = x - centre, dy = y - centre;
          // p came from R(-step) p and goes to R(step) p.
          vm.at(x, y, 0) = dx - (std::cos(step) * dx + std::sin(step) * dy);
          vm.at(x, y, 1) = dy - (-std::sin(step) * dx + std::cos(step) * dy);
          vp.at(x, y, 0) = std::cos(step) * dx - std::sin(step) * dy - dx;
          vp.at(x, y, 1) = std::sin(step) * dx + std::cos(step) * dy - dy;
        }
      guides.emplace_back(size, size, 1, 0.5f);
      angle.emplace_back(size, size, 1, truth.back());
      v_minus.push_back(std::move(vm));
      v_plus.push_back(std::move(vp));
    }
    chi.emplace_back(size, size, 1, 1.0f);
    shot.style = style.view();
    shot.guide_names = {"shade"};
    shot.style_guides = {style_guide.view()};
    shot.guide_weights = {1.0f};
    for (int t = 0; t < frames; ++t)
      shot.frames.push_back({{guides[t].view()}, v_minus[t].view(), v_plus[t].view(), chi[0].view(), chi[0].view(), {}});
  }

  void orient() {
    shot.style_orientation = style_angle.view();
    for (std::size_t t = 0; t < shot.frames.size(); ++t) shot.frames[t].orientation = angle[t].view();
  }

  // Median over frames and coherent pixels (coherence > 0.5, 6 px inside the
  // picture) of the axial angle between the output's hatching (structure
  // tensor) and the field, in degrees.
  double median_angle_error(const std::vector<Image>& out) const {
    std::vector<double> errors;
    for (std::size_t t = 0; t < out.size(); ++t) {
      const Image o = orientation_from_tensor(structure_tensor(out[t].view(), 2.0f).view());
      for (int y = 6; y < size - 6; ++y)
        for (int x = 6; x < size - 6; ++x) {
          if (o.at(x, y, 1) <= 0.5f) continue;
          double d = std::fmod(std::abs(double(o.at(x, y, 0)) - truth[t]), double(kPi));
          errors.push_back(std::min(d, kPi - d) * 180 / kPi);
        }
    }
    if (errors.empty()) return 90;
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
    return errors[errors.size() / 2];
  }
};

}  // namespace

// The field starts at 60 degrees and turns 4 degrees per frame (to 88):
// the hatching follows it within 10 degrees (median), and without the
// orientation fields it stays at the exemplar's 0 and the test fails.
TEST(TciaOrientation, HatchingFollowsATurningOrientationField) {
  TurningHatching oriented(8, 4.0f, 60.0f), plain(8, 4.0f, 60.0f);
  oriented.orient();
  const double with = oriented.median_angle_error(stylize_shot(oriented.shot, test::fast_options(2)));
  const double without = plain.median_angle_error(stylize_shot(plain.shot, test::fast_options(2)));
  RecordProperty("median_angle_error", std::to_string(with) + " deg; without orientation " + std::to_string(without));
  std::printf("angle error %f vs without %f\n", with, without);
  EXPECT_LE(with, 10.0);
  EXPECT_GT(without, 10.0);
}

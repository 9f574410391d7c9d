// Color Me Noisy: the rigid MLS pre-deformation, the noise pyramid, the
// local noise map and determinism. (Spectra: tests/python/test_noisy.py.)
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tempera/engine/error.hpp"
#include "tempera/methods/noisy/noisy.hpp"

using namespace tempera;

namespace {

Image noise_image(int w, int h, int c, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Image img(w, h, c);
  for (std::size_t i = 0; i < img.pixel_count() * c; ++i) img.data()[i] = u(rng);
  return img;
}

NoisyOptions fast(float noise) {
  NoisyOptions o = default_noisy_options();
  o.noise = noise;
  o.synthesis.threads = 2;
  return o;
}

}  // namespace

TEST(Mls, ZeroShiftsGiveTheIdentity) {
  MlsLattice lattice = random_lattice(120, 90, 40, 0, 0, 1);
  const Image map = mls_backward_map(lattice, 120, 90);
  for (int y = 0; y < 90; y += 7)
    for (int x = 0; x < 120; x += 7) {
      EXPECT_NEAR(map.at(x, y, 0), x, 1e-3);
      EXPECT_NEAR(map.at(x, y, 1), y, 1e-3);
    }
}

TEST(Mls, NodesLandOnTheirTargets) {
  const MlsLattice lattice = random_lattice(200, 150, 50, 15, 25, 2);
  for (std::size_t i = 0; i < lattice.rest.size(); ++i) {
    const Point2 back = rigid_mls(lattice.moved, lattice.rest, lattice.moved[i]);
    EXPECT_NEAR(back.x, lattice.rest[i].x, 0.5);
    EXPECT_NEAR(back.y, lattice.rest[i].y, 0.5);
    const float shift = std::hypot(lattice.moved[i].x - lattice.rest[i].x, lattice.moved[i].y - lattice.rest[i].y);
    EXPECT_GE(shift, 15 - 1e-3);
    EXPECT_LE(shift, 25 + 1e-3);
  }
}

TEST(Mls, JacobianStaysNearRigid) {
  // Singular values of the map's Jacobian, by central differences, over the
  // image: the paper's 50 px lattice with 15-25 px moves.
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const MlsLattice lattice = random_lattice(300, 200, 50, 15, 25, seed);
    const Image map = mls_backward_map(lattice, 300, 200);
    for (int y = 2; y < 198; y += 3)
      for (int x = 2; x < 298; x += 3) {
        const double a = (map.at(x + 1, y, 0) - map.at(x - 1, y, 0)) / 2, b = (map.at(x, y + 1, 0) - map.at(x, y - 1, 0)) / 2;
        const double c = (map.at(x + 1, y, 1) - map.at(x - 1, y, 1)) / 2, d = (map.at(x, y + 1, 1) - map.at(x, y - 1, 1)) / 2;
        const double s1 = std::sqrt(((a - d) * (a - d) + (b + c) * (b + c))) / 2, s2 = std::sqrt(((a + d) * (a + d) + (b - c) * (b - c))) / 2;
        const double smax = s1 + s2, smin = std::abs(s2 - s1);
        ASSERT_GE(smin, 0.6) << "at " << x << "," << y << " seed " << seed;
        ASSERT_LE(smax, 1.6) << "at " << x << "," << y << " seed " << seed;
      }
  }
}

TEST(Noisy, PyramidFollowsTheNoiseWidth) {
  EXPECT_EQ(noisy_levels(1.0f), 1);
  EXPECT_EQ(noisy_levels(1.3f), 3);   // 0.85^-2 = 1.38 >= 1.3
  EXPECT_EQ(noisy_levels(4.3f), 10);  // 0.85^-9 = 4.33
  const auto w = noisy_box_widths(2.2f);
  EXPECT_FLOAT_EQ(w.front(), 1.0f);
  EXPECT_NEAR(w.back(), 2.2f, 1e-5);
  for (std::size_t i = 1; i < w.size(); ++i) EXPECT_GT(w[i], w[i - 1]);
}

TEST(Noisy, NoNoiseIsTheReferenceAndFramesDifferOtherwise) {
  const Image style = noise_image(64, 64, 3, 3), reference = noise_image(48, 40, 3, 4);
  const Image same = noisy_frame(style.view(), reference.view(), 1, fast(0.0f));
  for (std::size_t i = 0; i < same.pixel_count() * 3; ++i) ASSERT_EQ(same.data()[i], reference.data()[i]);
  const Image a = noisy_frame(style.view(), reference.view(), 1, fast(2.2f));
  const Image b = noisy_frame(style.view(), reference.view(), 2, fast(2.2f));
  double diff = 0;
  for (std::size_t i = 0; i < a.pixel_count() * 3; ++i) diff += std::abs(a.data()[i] - b.data()[i]);
  EXPECT_GT(diff / (a.pixel_count() * 3), 0.01);  // consecutive frames differ
}

TEST(Noisy, SameSeedAndFrameGiveTheSameFrameForAnyThreadCount) {
  const Image style = noise_image(64, 64, 3, 5), reference = noise_image(48, 40, 3, 6);
  NoisyOptions one = fast(3.1f), two = fast(3.1f);
  one.synthesis.threads = 1;
  const Image a = noisy_frame(style.view(), reference.view(), 7, one), b = noisy_frame(style.view(), reference.view(), 7, two);
  for (std::size_t i = 0; i < a.pixel_count() * 3; ++i) ASSERT_EQ(a.data()[i], b.data()[i]);
}

TEST(Noisy, PixelsBelowOneInTheNoiseMapAreTheReferenceBitForBit) {
  const Image style = noise_image(64, 64, 3, 7), reference = noise_image(60, 40, 3, 8);
  Image map(60, 40, 1);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 60; ++x) map.at(x, y, 0) = x < 30 ? 0.1f : 1.0f;  // f_p = 0.31 left, 3.1 right
  const Image out = noisy_frame(style.view(), reference.view(), 3, fast(3.1f), map.view());
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 30; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(out.at(x, y, c), reference.at(x, y, c));
  double changed = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 34; x < 60; ++x)
      for (int c = 0; c < 3; ++c) changed += std::abs(out.at(x, y, c) - reference.at(x, y, c));
  EXPECT_GT(changed / (40 * 26 * 3), 0.01);
}

TEST(Noisy, BadInputNamesTheProblem) {
  const Image style = noise_image(32, 32, 3, 9), grey = noise_image(32, 32, 1, 10), map(10, 10, 1);
  EXPECT_THROW(noisy_frame(style.view(), grey.view(), 1, fast(2)), ValueError);
  EXPECT_THROW(noisy_frame(style.view(), style.view(), 1, fast(-1)), ValueError);
  EXPECT_THROW(noisy_frame(style.view(), style.view(), 1, fast(2), map.view()), ValueError);
}

TEST(Noisy, DihedralCopiesTurnAndMirror) {
  const Image img = noise_image(5, 3, 2, 11);
  const Image mirrored = dihedral_copy(img.view(), 1), turned = dihedral_copy(img.view(), 2);
  EXPECT_EQ(turned.width(), 3);
  EXPECT_EQ(turned.height(), 5);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) {
      EXPECT_EQ(mirrored.at(4 - x, y, 1), img.at(x, y, 1));
      EXPECT_EQ(turned.at(2 - y, x, 1), img.at(x, y, 1));  // a quarter turn clockwise
    }
  const Image round = dihedral_copy(dihedral_copy(img.view(), 6).view(), 2);  // 3 turns then 1
  for (std::size_t i = 0; i < img.pixel_count() * 2; ++i) ASSERT_EQ(round.data()[i], img.data()[i]);
}

TEST(Noisy, RotationsAndReflectionsChangeTheFrameAndStayDeterministic) {
  // A striped medium (stripes along x): with its turns and mirrors the source
  // set also holds stripes along y, which the plain exemplar does not.
  Image style(64, 64, 3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) style.at(x, y, c) = (y / 3) % 2 ? 0.9f : 0.1f + 0.1f * float((x * 7 + c) % 3);
  const Image reference = dihedral_copy(Image::copy_of(style.view()).view(), 2);  // R with stripes along y
  Image r(48, 40, 3);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 48; ++x)
      for (int c = 0; c < 3; ++c) r.at(x, y, c) = reference.at(x + 4, y + 6, c);
  NoisyOptions plain = fast(2.2f), turned = fast(2.2f);
  turned.rotations = turned.reflections = true;
  const Image a = noisy_frame(style.view(), r.view(), 4, plain), b = noisy_frame(style.view(), r.view(), 4, turned);
  double diff = 0, err_a = 0, err_b = 0;
  for (std::size_t i = 0; i < a.pixel_count() * 3; ++i) {
    diff += std::abs(a.data()[i] - b.data()[i]);
    err_a += std::abs(a.data()[i] - r.data()[i]);
    err_b += std::abs(b.data()[i] - r.data()[i]);
  }
  EXPECT_GT(diff / (a.pixel_count() * 3), 0.01);
  EXPECT_LT(err_b, err_a);  // the turned copies fit R's stripes
  NoisyOptions one = turned;
  one.synthesis.threads = 1;
  const Image again = noisy_frame(style.view(), r.view(), 4, one);
  for (std::size_t i = 0; i < b.pixel_count() * 3; ++i) ASSERT_EQ(again.data()[i], b.data()[i]);
}

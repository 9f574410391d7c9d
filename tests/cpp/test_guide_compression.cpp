// The guide projection (guide_compression.hpp) reads the weighted guide
// layers in place, and synthesis tells its caller when the guides may go.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "tempera/engine/guide_compression.hpp"
#include "tempera/engine/solver.hpp"
#include "tempera/engine/synthesis.hpp"
#include "test_inputs.hpp"

using namespace tempera;
using tempera::test_inputs::noise_texture;

namespace {

// The layers stacked along channels, each scaled: what the projection used to
// be given as one image.
Image stacked(const WeightedGuides& g) {
  Image out(g.layers.front().width, g.layers.front().height, g.channels());
  for (std::size_t i = 0; i < out.pixel_count(); ++i) {
    float* o = out.data() + i * std::size_t(out.channels());
    for (std::size_t k = 0; k < g.layers.size(); ++k)
      for (int c = 0; c < g.layers[k].channels; ++c)
        *o++ = g.layers[k].data[i * std::size_t(g.layers[k].channels) + c] * g.scales[k];
  }
  return out;
}

Image rows(const Image& top, const Image& bottom) {
  Image out(top.width(), top.height() + bottom.height(), top.channels());
  std::memcpy(out.data(), top.data(), sizeof(float) * top.pixel_count() * top.channels());
  std::memcpy(out.data() + top.pixel_count() * top.channels(), bottom.data(),
              sizeof(float) * bottom.pixel_count() * bottom.channels());
  return out;
}

bool same(const Image& a, const Image& b) {
  return a.width() == b.width() && a.height() == b.height() && a.channels() == b.channels() &&
         std::equal(a.data(), a.data() + a.pixel_count() * a.channels(), b.data());
}

}  // namespace

// Layers of 3, 1 and 2 channels with their weights' square roots, read in
// place, give bit for bit the projection of their scaled stack; two sources
// fit like their rows stacked into one image (the subsample continues across
// them). Sizes are not multiples of the subsample step, so its phase matters.
TEST(GuideCompression, LayersReadInPlaceProjectLikeTheirStack) {
  const Image a1 = noise_texture(301, 257, 3, 1), b1 = noise_texture(301, 257, 1, 2), c1 = noise_texture(301, 257, 2, 3);
  const Image a2 = noise_texture(301, 190, 3, 4), b2 = noise_texture(301, 190, 1, 5), c2 = noise_texture(301, 190, 2, 6);
  const Image at = noise_texture(233, 311, 3, 7), bt = noise_texture(233, 311, 1, 8), ct = noise_texture(233, 311, 2, 9);
  const std::vector<float> scales = {std::sqrt(0.5f), std::sqrt(2.0f), 1.0f};
  const WeightedGuides s1{{a1.view(), b1.view(), c1.view()}, scales}, s2{{a2.view(), b2.view(), c2.view()}, scales};
  const WeightedGuides target{{at.view(), bt.view(), ct.view()}, scales};
  ASSERT_EQ(target.channels(), 6);

  const Image st1 = stacked(s1), st2 = stacked(s2), stt = stacked(target), both = rows(st1, st2);
  const WeightedGuides as_one{{both.view()}, {1.0f}}, as_one_target{{stt.view()}, {1.0f}};
  const GuideProjection in_place = fit_guide_projection({s1, s2}, target, 0.9);
  const GuideProjection from_stack = fit_guide_projection({as_one}, as_one_target, 0.9);
  EXPECT_EQ(in_place.mean, from_stack.mean);
  EXPECT_EQ(in_place.components, from_stack.components);
  EXPECT_EQ(in_place.kept_variance, from_stack.kept_variance);
  EXPECT_LT(in_place.output_channels(), 6);  // noise: 0.9 of the variance needs fewer than all six

  const WeightedGuides st1_view{{st1.view()}, {1.0f}}, stt_view{{stt.view()}, {1.0f}};
  EXPECT_TRUE(same(in_place.apply(s1), from_stack.apply(st1_view)));
  EXPECT_TRUE(same(in_place.apply(target), from_stack.apply(stt_view)));
}

// Correlated light-path buffers compress: a layer that repeats another adds
// no variance, and the kept fraction reaches what was asked.
TEST(GuideCompression, KeepsTheVarianceAskedWithFewerChannels) {
  const Image a = noise_texture(120, 90, 3, 11), t = noise_texture(100, 80, 3, 12);
  const WeightedGuides source{{a.view(), a.view()}, {1.0f, 1.0f}}, target{{t.view(), t.view()}, {1.0f, 1.0f}};
  const GuideProjection proj = fit_guide_projection({source}, target, 0.999);
  EXPECT_LE(proj.output_channels(), 3);
  EXPECT_GE(proj.kept_variance, 0.999);
}

// The caller's guides_read hook runs once, after which the solver never reads
// the guide images: poisoning them there leaves the result bit for bit as it
// was (the CLI frees its decoded guides there).
TEST(GuideCompression, GuidesAreNotReadAfterTheCallerIsToldSo) {
  const Image style = noise_texture(48, 40, 3, 21);
  Image sg1 = noise_texture(48, 40, 3, 22), sg2 = noise_texture(48, 40, 2, 23);
  Image tg1 = noise_texture(56, 36, 3, 24), tg2 = noise_texture(56, 36, 2, 25);
  SynthesisOptions opt;
  opt.em_iterations = 2;
  opt.threads = 2;
  auto input = [&] {
    SynthesisInput in;
    in.style = style.view();
    in.guides.add("a", sg1.view(), tg1.view(), 0.5f);
    in.guides.add("b", sg2.view(), tg2.view(), 2.0f);
    return in;
  };
  for (const double variance : {0.999, 1.0}) {  // projected, and stacked as given
    opt.guide_variance = variance;
    const SynthesisResult plain = synthesize(input(), opt);
    SynthesisInput told = input();
    int exemplar_calls = 0, calls = 0;
    const auto poison = [](std::initializer_list<Image*> images) {
      for (Image* g : images)
        std::fill(g->data(), g->data() + g->pixel_count() * g->channels(), std::numeric_limits<float>::quiet_NaN());
    };
    told.exemplar_guides_read = [&] {  // the exemplar's first, the target's still read after
      ++exemplar_calls;
      poison({&sg1, &sg2});
    };
    told.guides_read = [&] {
      ++calls;
      poison({&tg1, &tg2});
    };
    const SynthesisResult freed = synthesize(told, opt);
    EXPECT_EQ(exemplar_calls, 1) << "variance " << variance;
    EXPECT_EQ(calls, 1) << "variance " << variance;
    EXPECT_TRUE(same(plain.image, freed.image)) << "variance " << variance;
    sg1 = noise_texture(48, 40, 3, 22), sg2 = noise_texture(48, 40, 2, 23);
    tg1 = noise_texture(56, 36, 3, 24), tg2 = noise_texture(56, 36, 2, 25);
  }
}

// Nor is the style, the other large input, once the solver has its pyramids.
TEST(GuideCompression, InputsAreNotReadAfterTheCallerIsToldSo) {
  Image style = noise_texture(48, 40, 3, 31);
  const Image sg = noise_texture(48, 40, 3, 32), tg = noise_texture(56, 36, 3, 33);
  SynthesisOptions opt;
  opt.em_iterations = 2;
  opt.threads = 2;
  SynthesisInput in;
  in.style = style.view();
  in.guides.add("a", sg.view(), tg.view());
  const SynthesisResult plain = synthesize(in, opt);
  int calls = 0;
  in.inputs_read = [&] {
    ++calls;
    std::fill(style.data(), style.data() + style.pixel_count() * style.channels(),
              std::numeric_limits<float>::quiet_NaN());
  };
  const SynthesisResult freed = synthesize(in, opt);
  EXPECT_EQ(calls, 1);
  EXPECT_TRUE(same(plain.image, freed.image));
}

// A shot's frame: the light-path layers (no weight map) are merged by PCA,
// the temporal guide after them keeps its channels, and its map weighs it
// alone: under a zero map its target is not matched at all, under a map of
// ones it is. Per-level guide targets still name the input's layers.
TEST(GuideCompression, LayersBeforeAWeightMapAreMergedAndTheMappedOneKept) {
  const Image style = noise_texture(48, 40, 3, 31), sg = noise_texture(48, 40, 3, 32);
  const Image tg = noise_texture(56, 36, 3, 33), t1 = noise_texture(56, 36, 3, 34), t2 = noise_texture(56, 36, 3, 35);
  const Image zeros(56, 36, 1, 0.0f), ones(56, 36, 1, 1.0f);
  SynthesisOptions opt;
  opt.em_iterations = 2;
  opt.threads = 2;
  opt.guide_variance = 0.999;
  auto input = [&](const Image& temporal_target, const Image& map) {
    SynthesisInput in;
    in.style = style.view();
    in.guides.add("FULL", sg.view(), tg.view(), 1.0f);
    in.guides.add("LDE", sg.view(), tg.view(), 1.0f);  // repeats FULL: merged, it adds no channel
    in.guides.add("temporal", style.view(), temporal_target.view(), 0.5f);
    in.target_weight_maps = {ImageView{}, ImageView{}, map.view()};
    return in;
  };
  const Solver solver(input(t1, ones), opt);
  EXPECT_LE(solver.guide_channels(), 3 + 3);  // all 9 kept before
  EXPECT_TRUE(same(synthesize(input(t1, zeros), opt).image, synthesize(input(t2, zeros), opt).image));
  EXPECT_FALSE(same(synthesize(input(t1, ones), opt).image, synthesize(input(t2, ones), opt).image));

  const int l = solver.levels() - 1;
  const Image level_target(solver.target_width(l), solver.target_height(l), 3, 0.5f);
  LevelStart start;
  start.guide_targets = {{2, &level_target}};
  EXPECT_NO_THROW(solver.solve_level(l, start));
  start.guide_targets = {{0, &level_target}};
  EXPECT_THROW(solver.solve_level(l, start), ValueError);  // merged: its channels are gone
}

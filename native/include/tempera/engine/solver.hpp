#pragma once
// The engine driven level by level. The constructor validates the input and
// builds the plan: pyramids of every input (exemplars stacked into one atlas
// per level, guides weighted and PCA-compressed, masks, orientations, labels,
// weight maps, the reference and the hard constraints) at the options' level
// ratio. solve_level() then runs the EM iterations of one level from a given
// start (a field from another level or frame, a starting image, injected
// candidates) and returns the field, the image and the statistics; it keeps
// no state between calls, so a method may solve levels in any order, as often
// as it likes (per frame, per sweep); only a `last_use` solve changes the
// solver: it frees that level (below).
//
//   Solver solver(input, options);
//   LevelResult r = solver.solve_level(solver.coarsest(), {});
//   for (int l = solver.coarsest() - 1; l >= 0; --l) {
//     OffsetField up = solver.resample(r.field, l + 1, l);
//     r = solver.solve_level(l, {&up});
//   }
//
// A method that solves each level once (synthesize()) marks the solve
// `last_use` and hands the start field over (`take_field`), so the plan's
// level and the carried field are freed while the level runs.
#include <memory>
#include <vector>

#include "tempera/engine/synthesis.hpp"

namespace tempera {

struct LevelStart {
  const OffsetField* field = nullptr;  // null: cold start (guides-only match, or the reference)
  const Image* image = nullptr;        // B' to start from; null: voted from the field
  // With `image`: only where this mask (level size, 1 channel) is > 0.5 does
  // `image` replace the B' voted from the field.
  const Image* image_mask = nullptr;
  // With `field` (or `take_field`): where this mask (level size, 1 channel)
  // is > 0.5 the start field's match is replaced by one found on the guides
  // alone (a random one without guides), e.g. a warm start's disoccluded pixels.
  const Image* restart_mask = nullptr;
  const CandidateList* candidates = nullptr;  // extra candidates (atlas positions at this level)
  // Hard constraints of this level alone (level size), instead of the
  // input's: pixels held at `fixed_values` (the style's channels), e.g. Color
  // Me Noisy's pixels that join the synthesis only at a finer level.
  const Image* fixed_mask = nullptr;
  const Image* fixed_values = nullptr;
  // Target images of guide layers at this level (layer index, level-size
  // image with the layer's channels), replacing the input's: guides that a
  // method recomputes per level and sweep, such as Bénard's temporal term on
  // the previous frame's result. Needs uncompressed guides (guide_variance 1).
  std::vector<std::pair<int, const Image*>> guide_targets;
  // Instead of `field`: a start field the solver moves from (one full-size
  // field less while the level runs). Left empty.
  OffsetField* take_field = nullptr;
  // No later call solves (or measures) this level: the solver frees the
  // level's float pyramids of the plan as soon as its features are built
  // (the coarse-to-fine schedule, so that the peak grows with the pixels and
  // not with pixels x levels). Sizes, layouts and resample() stay usable.
  bool last_use = false;
};

struct LevelResult {
  OffsetField field;
  Image image;
  LevelStats stats;
};

class Solver {
 public:
  Solver(const SynthesisInput& input, const SynthesisOptions& options);
  ~Solver();
  Solver(const Solver&) = delete;
  Solver& operator=(const Solver&) = delete;

  int levels() const;
  int coarsest() const { return levels() - 1; }
  int target_width(int level) const;
  int target_height(int level) const;
  const SourceLayout& layout(int level) const;
  int guide_channels() const;
  double kept_guide_variance() const;
  // EM iterations and PatchMatch sweeps of a level (the options' schedules).
  int em_iterations(int level) const;
  int pm_iterations(int level) const;

  // `field` of level `from` at level `to` (any two levels, either way).
  OffsetField resample(const OffsetField& field, int from, int to) const;
  // `field` of the previous frame at `level`, advected along that level's V-
  // (velocity in level pixels, x right, y down; Bénard §3.3).
  OffsetField advect(const OffsetField& field, int level, const ImageView& velocity_backward) const;
  // Atlas position of (exemplar, x, y) at `level` (exemplar pixels at that level).
  void to_atlas(int level, int exemplar, float x, float y, float& ax, float& ay) const;
  ExemplarMatch match(int level, const OffsetField& field, std::size_t i) const;
  // Energy of `field` with the image `image` as B' (mean patch distance over
  // the active pixels).
  double energy(int level, const OffsetField& field, const Image& image) const;

  // Runs level `level` from `start`. `progress` gets the fraction of this
  // level done; returning false cancels (CancelledError).
  LevelResult solve_level(int level, const LevelStart& start,
                          const std::function<bool(double)>& progress = {}) const;

 private:
  struct Plan;
  struct Level;
  void build_level(int level, Level& out, const LevelStart* start = nullptr) const;
  // Patch space of `level` without features: for moving fields (angles, margins).
  PatchSpace geometry(int level, FeatureImage& source, FeatureImage& target) const;
  OffsetField cold_start(int level, Level& lv, Image& bprime) const;
  void restart_masked(int level, const Image& mask, const Level& lv, OffsetField& field) const;
  void match_on_guides(const Level& lv, const SearchConstraints& constraints, OffsetField& field,
                       int iterations) const;
  void fix_pixels(int level, const Level& lv, const Image* values, OffsetField& field, Image& bprime) const;
  void set_target_style(Level& lv, const Image& bprime) const;
  void allocate_features(Level& lv, const std::vector<ChannelWrite>& source_writes,
                         const std::vector<ChannelWrite>& target_writes, bool in_float) const;
  void mark_weighted_patches(Level& lv) const;
  void add_guide_target_writes(int level, const LevelStart& start, std::vector<ChannelWrite>& writes) const;
  std::unique_ptr<Plan> plan_;
  SynthesisOptions options_;
  EnergyTerms terms_;
};

}  // namespace tempera

#include "tempera/engine/synthesis.hpp"

#include <chrono>

#include "tempera/engine/error.hpp"
#include "tempera/engine/patch_usage.hpp"
#include "tempera/engine/solver.hpp"

namespace tempera {
namespace {

// `result` completed with the finest level's field, image and figures.
SynthesisResult finest_result(const Solver& solver, LevelResult level, SynthesisResult result,
                              std::chrono::steady_clock::time_point t_start) {
  result.image = std::move(level.image);
  result.field = std::move(level.field);
  result.layout = solver.layout(0);
  result.source_coverage = result.levels.back().source_coverage;
  result.guide_channels = solver.guide_channels();
  result.kept_guide_variance = solver.kept_guide_variance();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return result;
}

}  // namespace

// The whole solve: coarse to fine, each level started from the coarser
// level's field (the cold start at the coarsest).
SynthesisResult synthesize(const SynthesisInput& in, const SynthesisOptions& opt, const ProgressCallback& progress) {
  const auto t_start = std::chrono::steady_clock::now();
  const Solver solver(in, opt);
  double total_work = 0, done_work = 0;
  for (int l = 0; l < solver.levels(); ++l)
    total_work += double(solver.target_width(l)) * solver.target_height(l) * solver.em_iterations(l);
  SynthesisResult result;
  LevelResult level;
  for (int l = solver.coarsest(); l >= 0; --l) {
    const double work = double(solver.target_width(l)) * solver.target_height(l) * solver.em_iterations(l);
    auto report = [&](double fraction) {
      return !progress || progress(std::min(1.0, (done_work + fraction * work) / total_work));
    };
    // Each level is solved once: its plan is freed as it starts, the coarser
    // result before it, and the start field is handed over, not copied.
    LevelStart start;
    start.last_use = true;
    OffsetField up;
    if (l != solver.coarsest()) {
      up = solver.resample(level.field, l + 1, l);
      level = LevelResult();
      start.take_field = &up;
    }
    level = solver.solve_level(l, start, report);
    done_work += work;
    result.levels.push_back(level.stats);
  }
  return finest_result(solver, std::move(level), std::move(result), t_start);
}

SynthesisResult synthesize_warm(const SynthesisInput& in, const SynthesisOptions& opt,
                                const OffsetField& previous_field, const ImageView& velocity_backward,
                                const ImageView& visible, const ProgressCallback& progress) {
  const auto t_start = std::chrono::steady_clock::now();
  const Solver solver(in, opt);
  if (previous_field.width != solver.target_width(0) || previous_field.height != solver.target_height(0))
    throw ValueError(concat("the previous frame's field is ", previous_field.width, "x", previous_field.height,
                            " but the target is ", solver.target_width(0), "x", solver.target_height(0)));
  LevelStart start;
  start.last_use = true;
  OffsetField advected = solver.advect(previous_field, 0, velocity_backward);
  start.take_field = &advected;
  Image hidden;  // χ- below 0.5: restarted
  if (!visible.empty()) {
    if (visible.width != advected.width || visible.height != advected.height || visible.channels != 1)
      throw ValueError(concat("the visibility must be ", advected.width, "x", advected.height, " with 1 channel, got ",
                              visible.width, "x", visible.height, "x", visible.channels));
    hidden = Image(visible.width, visible.height, 1);
    for (std::size_t i = 0; i < hidden.pixel_count(); ++i) hidden.data()[i] = visible.data[i] < 0.5f ? 1.0f : 0.0f;
    start.restart_mask = &hidden;
  }
  LevelResult level = solver.solve_level(0, start, progress);
  SynthesisResult result;
  result.levels = {level.stats};
  return finest_result(solver, std::move(level), std::move(result), t_start);
}

}  // namespace tempera

// StyLit's error budget (thesis §8.3.3): repeated reversed retrieval that
// accepts assignments only below the knee of the sorted error curve, forward
// retrieval for what remains.
#include <algorithm>
#include <cmath>

#include "tempera/engine/patch_usage.hpp"
#include "tempera/engine/order_statistics.hpp"
#include "tempera/engine/reversed_retrieval.hpp"

namespace tempera {
namespace {

// Hyperbola f(x) = 1 / (a - b x) fitted to (x, y) by Gauss-Newton, starting
// from the weighted linear fit of 1/y = a - b x. Returns {a, b}.
std::pair<double, double> fit_hyperbola(const std::vector<double>& xs, const std::vector<double>& ys) {
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const double w = ys[i] * ys[i], inv = 1.0 / ys[i];  // d(1/y) = dy / y^2
    sw += w, sx += w * xs[i], sy += w * inv, sxx += w * xs[i] * xs[i], sxy += w * xs[i] * inv;
  }
  const double det = sw * sxx - sx * sx;
  if (std::abs(det) < 1e-12) return {1.0, 0.0};
  double slope = (sw * sxy - sx * sy) / det;
  double a = (sy - slope * sx) / sw, b = -slope;
  for (int it = 0; it < 20; ++it) {
    double jtj[3] = {0, 0, 0}, jtr[2] = {0, 0};
    for (std::size_t i = 0; i < xs.size(); ++i) {
      const double den = a - b * xs[i];
      if (den <= 1e-9) return {a, b};
      const double f = 1.0 / den, ja = -f * f, jb = xs[i] * f * f, r = ys[i] - f;
      jtj[0] += ja * ja, jtj[1] += ja * jb, jtj[2] += jb * jb;
      jtr[0] += ja * r, jtr[1] += jb * r;
    }
    const double d = jtj[0] * jtj[2] - jtj[1] * jtj[1];
    if (std::abs(d) < 1e-18) break;
    double da = (jtj[2] * jtr[0] - jtj[1] * jtr[1]) / d, db = (jtj[0] * jtr[1] - jtj[1] * jtr[0]) / d;
    // Keep the pole to the right of the data (a - b x > 0 on [0, 1]).
    double na = a + da, nb = b + db;
    for (int h = 0; h < 30 && (na <= 0 || na - nb <= 1e-6); ++h) na = a + (da *= 0.5), nb = b + (db *= 0.5);
    if (na <= 0 || na - nb <= 1e-6) break;
    a = na, b = nb;
    if (std::abs(da) + std::abs(db) < 1e-9) break;
  }
  return {a, b};
}

constexpr std::size_t kKneeSamples = 1024;

}  // namespace

std::vector<std::size_t> knee_sample_ranks(std::size_t n) {
  if (n < 8) return {};
  // An even subsample of the curve, its last error included.
  const std::size_t m = std::min(n, kKneeSamples);
  std::vector<std::size_t> ranks(m);
  for (std::size_t i = 0; i < m; ++i) ranks[i] = i * (n - 1) / (m - 1);
  return ranks;
}

std::size_t error_knee(std::size_t n, const std::vector<float>& samples) {
  if (n < 8 || samples.size() != std::min(n, kKneeSamples)) return n;
  const double top = samples.back();
  if (!(top > 0)) return n;
  // Normalized axes: x in [0, 1], y = error / max error.
  const std::size_t m = samples.size();
  std::vector<double> xs(m), ys(m);
  for (std::size_t i = 0; i < m; ++i) {
    xs[i] = double(i * (n - 1) / (m - 1)) / double(n - 1);
    ys[i] = std::max(double(samples[i]) / top, 1e-4);
  }
  // The paper's knee: where the fitted hyperbola's slope reaches 1.
  const auto [a, b] = fit_hyperbola(xs, ys);
  double knee = 1.0;
  if (b > 1e-9) knee = std::clamp((a - std::sqrt(b)) / b, 0.0, 1.0);
  // A hyperbola cannot follow a step (two populations of errors, e.g. good
  // matches and forced ones): there the fit flattens and its knee slides to the
  // end. The first point where the smoothed empirical slope rises through 1
  // catches the step; a true hyperbola crosses slope 1 at the same place. A
  // rise at the very start (a few exact matches, then the rest) is not a knee:
  // taken as one, it retired 99% of the sources in one EM iteration and none
  // in the next, so frames flipped between two energies.
  const std::size_t w = std::max<std::size_t>(2, m / 64);
  bool below = false;
  for (std::size_t i = 0; i + w < m; ++i) {
    const double slope = (ys[i + w] - ys[i]) / (xs[i + w] - xs[i]);
    if (slope < 1.0) {
      below = true;
    } else if (below) {
      knee = std::min(knee, xs[i + w / 2]);
      break;
    }
  }
  return std::clamp<std::size_t>(std::size_t(std::ceil(knee * double(n - 1))), 1, n);
}

std::size_t error_knee(const std::vector<float>& sorted) {
  std::vector<float> samples;
  for (std::size_t j : knee_sample_ranks(sorted.size())) samples.push_back(sorted[j]);
  return error_knee(sorted.size(), samples);
}

UsageStats retrieve_with_budget(const PatchSpace& space, const SearchConstraints& cons, OffsetField& nnf,
                                const ReversedRetrievalParams& params, std::uint64_t stream,
                                const std::vector<std::int32_t>* earlier_sources) {
  ReversedRetrieval rr(space, cons, nnf, params, stream);
  rr.set_earlier_sources(earlier_sources);
  rr.eligible() = cons.source_valid;
  UsageStats stats;
  // The round's candidate errors, read in place: the knee needs about a
  // thousand of their ranks, not a sorted copy (order_statistics.hpp).
  const auto errors_in = [&rr](std::size_t begin, std::size_t end, auto&& f) {
    for (std::size_t p = begin; p < end; ++p)
      if (rr.eligible()[p] && rr.candidate()[p] != kNoTarget) f(rr.candidate_dist()[p]);
  };
  while (stats.rounds < params.max_rounds &&
         double(rr.assigned_count()) < params.coverage_goal * double(rr.active())) {
    rr.search(stats.rounds++);
    const RadixSelect errors(errors_in, rr.candidate().size(), params.threads);
    const std::size_t n = errors.size();
    if (n == 0) break;
    const std::size_t knee = error_knee(n, errors.values_at(knee_sample_ranks(n)));
    const float knee_error = errors.values_at({knee - 1}).front();
    // Sources whose best open target is already past the knee only get worse
    // as targets fill up: retire them.
    for (std::size_t p = 0; p < rr.candidate().size(); ++p)
      if (rr.eligible()[p] && rr.candidate()[p] != kNoTarget && rr.candidate_dist()[p] > knee_error)
        rr.eligible()[p] = 0;
    // The budget T is the sum of all candidate errors below the knee; the
    // winners below the knee are a subset of those candidates, so taking all of
    // them keeps the total under T (thesis eq. 8.4).
    std::size_t taken = 0;
    rr.for_each_winner([&](const Assignment& a) {
      if (a.dist > knee_error) return;
      rr.assign(a);
      ++taken;
    });
    if (taken == 0) break;
  }
  stats.covered = double(rr.assigned_count()) / double(std::max<std::size_t>(1, rr.active()));
  stats.wide_searches = rr.wide_searches();
  return stats;  // targets not covered keep their forward match
}

namespace {

class ErrorBudget final : public EnergyTerm {
 public:
  ErrorBudget(double coverage, int max_rounds) : coverage_(coverage), max_rounds_(max_rounds) {}
  const char* name() const override { return "budget"; }
  UsageStats reassign(const LevelContext& c, OffsetField& field, std::uint64_t stream) const override {
    ReversedRetrievalParams rr;
    rr.coverage_goal = coverage_;
    rr.max_rounds = max_rounds_;
    rr.seed = c.seed;
    rr.threads = c.threads;
    return retrieve_with_budget(*c.space, *c.constraints, field, rr, stream, c.sources_before_search);
  }

 private:
  double coverage_;
  int max_rounds_;
};

}  // namespace

std::shared_ptr<const EnergyTerm> make_error_budget(double coverage, int max_rounds) {
  return std::make_shared<ErrorBudget>(coverage, max_rounds);
}

}  // namespace tempera

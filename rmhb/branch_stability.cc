#include "rmhb/branch_stability.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace rmhb {

BranchStability::BranchStability(const ContinuationProblem& problem, const ContinuationOptions& options,
                                 int unknowns)
    : problem_(problem), options_(options), unknowns_(unknowns) {
  if (options.stability_method == StabilityMethod::kMonodromy && !problem.monodromy) {
    monodromy_refused_ = true;
    note_ = "the monodromy was asked for, but the problem has no original equations (ContinuationProblem::monodromy)";
  }
  if (options.stability_method == StabilityMethod::kHill) monodromy_refused_ = true;
  if (options.stability_method == StabilityMethod::kMonodromy) hill_refused_ = true;
  if (!problem.monodromy) monodromy_refused_ = true;
}

bool BranchStability::Classify(const HarmonicBalanceProblem& problem, ContinuationPoint* point) {
  const auto start = std::chrono::steady_clock::now();
  bool done = false;
  if (point->solution.frequencies().size() != 1) {
    note_ = "quasi-periodic solutions have no period: neither Hill's method nor a monodromy matrix applies";
  } else {
    // Hill where it is cheap, the monodromy where it is not or Hill does
    // not apply, Hill at any size as the last resort.
    const bool hill_cheap = unknowns_ <= options_.max_hill_unknowns;
    if (!compared_ && options_.stability_method == StabilityMethod::kAuto && HillApplies() && !monodromy_refused_ &&
        unknowns_ <= options_.max_cross_check_unknowns)
      done = Compare(problem, point);
    if (!done && HillApplies() && (hill_cheap || monodromy_refused_)) done = TryHill(problem, point);
    if (!done && !monodromy_refused_) done = TryMonodromy(point);
    if (!done && HillApplies() && !hill_cheap && !monodromy_refused_) done = TryHill(problem, point);
  }
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return done;
}

namespace {

// Largest distance between two sets of multipliers, each of `a` paired with
// the nearest unused one of `b`; the trivial ones left out.
double MatchedDifference(const Multipliers& a, int trivial_a, const Multipliers& b, int trivial_b) {
  std::vector<bool> used(b.size(), false);
  if (trivial_b >= 0) used[trivial_b] = true;
  double worst = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (static_cast<int>(i) == trivial_a) continue;
    int best = -1;
    for (size_t j = 0; j < b.size(); ++j)
      if (!used[j] && (best < 0 || std::abs(b[j] - a[i]) < std::abs(b[best] - a[i]))) best = static_cast<int>(j);
    if (best < 0) return HUGE_VAL;
    used[best] = true;
    worst = std::max(worst, std::abs(b[best] - a[i]));
  }
  return worst;
}

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

bool BranchStability::Compare(const HarmonicBalanceProblem& problem, ContinuationPoint* point) {
  ContinuationPoint by_hill = *point;
  auto start = std::chrono::steady_clock::now();
  const bool hill = TryHill(problem, &by_hill);
  const double hill_seconds = Since(start);
  start = std::chrono::steady_clock::now();
  const bool monodromy = TryMonodromy(point);
  const double monodromy_seconds = Since(start);
  if (!hill || !monodromy) {
    if (hill) *point = by_hill;
    return hill || monodromy;  // the next point tries again
  }
  compared_ = true;
  char text[240];
  std::snprintf(text, sizeof text, "Hill %.3g ms, monodromy %.3g ms at the first point; multipliers agree to %.1e",
                1e3 * hill_seconds, 1e3 * monodromy_seconds,
                MatchedDifference(by_hill.multipliers, by_hill.trivial_multiplier, point->multipliers,
                                  point->trivial_multiplier));
  cross_check_ = text;
  if (unknowns_ <= options_.max_hill_unknowns) *point = by_hill, --monodromy_points_;
  else --hill_points_;
  return true;
}

bool BranchStability::TryHill(const HarmonicBalanceProblem& problem, ContinuationPoint* point) {
  try {
    const HillStabilityReport hill = HillStability(problem, point->solution, options_.hill);
    Finish(hill.multipliers, hill.trivial, StabilityMethod::kHill, point);
    ++hill_points_;
    return true;
  } catch (const std::invalid_argument& e) {
    // Outside the method's scope: the same for every point.
    hill_refused_ = true;
    note_ = e.what();
  } catch (const std::runtime_error& e) {
    // QZ did not converge: likely so at the next points too, and costly.
    note_ = e.what();
    hill_refused_ = ++hill_failures_ >= 2;
  }
  return false;
}

bool BranchStability::TryMonodromy(ContinuationPoint* point) {
  MonodromyResult r;
  try {
    r = problem_.monodromy(point->parameter, point->solution, problem_.period_multiple);
  } catch (const std::invalid_argument& e) {
    monodromy_refused_ = true;
    note_ = std::string("no monodromy: ") + e.what();
    return false;
  }
  if (!r.ok) {
    note_ = "the monodromy failed at " + problem_.parameter + " = " + std::to_string(point->parameter) + ": " +
            r.message;
    return false;
  }
  Finish(r.multipliers, r.trivial, StabilityMethod::kMonodromy, point);
  ++monodromy_points_;
  return true;
}

void BranchStability::Finish(const Multipliers& multipliers, int trivial, StabilityMethod method,
                             ContinuationPoint* p) const {
  // By decreasing modulus, the trivial one's index carried along.
  std::vector<int> order(multipliers.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return std::abs(multipliers[a]) > std::abs(multipliers[b]); });
  p->multipliers.clear();
  p->trivial_multiplier = -1;
  p->max_multiplier = 0;
  for (size_t i = 0; i < order.size(); ++i) {
    p->multipliers.push_back(multipliers[order[i]]);
    if (order[i] == trivial) p->trivial_multiplier = static_cast<int>(i);
    else p->max_multiplier = std::max(p->max_multiplier, std::abs(multipliers[order[i]]));
  }
  p->stability_method = method;
  const double band = options_.neutral_band;
  p->stability = p->max_multiplier < 1 - band   ? PointStability::kStable
                 : p->max_multiplier > 1 + band ? PointStability::kUnstable
                                                : PointStability::kNeutral;
  const double period = 2 * M_PI / p->solution.frequencies()[0];
  p->max_real_part = p->max_multiplier > 0 ? std::log(p->max_multiplier) / period : -HUGE_VAL;
}

}  // namespace rmhb

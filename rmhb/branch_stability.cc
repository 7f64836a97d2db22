#include "rmhb/branch_stability.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "rmhb/truncation_estimate.h"

namespace rmhb {

BranchStability::BranchStability(const ContinuationProblem& problem, const ContinuationOptions& options,
                                 int unknowns)
    : problem_(problem), options_(options), unknowns_(unknowns) {
  if (options.stability_method == StabilityMethod::kMonodromy && !problem.monodromy) {
    monodromy_refused_ = true;
    note_ = "the monodromy was asked for, but the problem has no original equations (ContinuationProblem::monodromy)";
  }
  const StabilityMethod m = options.stability_method;
  if (m != StabilityMethod::kAuto && m != StabilityMethod::kMonodromy) monodromy_refused_ = true;
  if (m != StabilityMethod::kAuto && m != StabilityMethod::kHill) hill_refused_ = true;
  if (m != StabilityMethod::kAuto && m != StabilityMethod::kHarmonicMonodromy) harmonic_refused_ = true;
  if (!problem.monodromy) monodromy_refused_ = true;
}

bool BranchStability::Classify(const HarmonicBalanceProblem& problem, ContinuationPoint* point) {
  const auto start = std::chrono::steady_clock::now();
  bool done = false;
  if (point->solution.frequencies().size() != 1) {
    note_ = "quasi-periodic solutions have no period: neither Hill's method nor a monodromy matrix applies";
  } else {
    // The linearisation's monodromy wherever it applies; else Hill where it
    // is cheap, the model's monodromy where it is not or Hill does not
    // apply, Hill at any size as the last resort.
    const bool hill_cheap = unknowns_ <= options_.max_hill_unknowns;
    if (!compared_ && options_.stability_method == StabilityMethod::kAuto) Compare(problem, point, &done);
    if (!done && !harmonic_refused_) done = TryHarmonic(problem, point);
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

bool BranchStability::Compare(const HarmonicBalanceProblem& problem, ContinuationPoint* point, bool* done) {
  // Each applicable method on a copy of the point, timed.
  struct Tried {
    const char* name;
    ContinuationPoint point;
    bool ok = false;
    double seconds = 0;
  };
  std::vector<Tried> tried;
  auto attempt = [&](const char* name, auto method) {
    tried.push_back({name, *point});
    const auto start = std::chrono::steady_clock::now();
    tried.back().ok = method(&tried.back().point);
    tried.back().seconds = Since(start);
    if (!tried.back().ok) tried.pop_back();
  };
  if (!harmonic_refused_) attempt("hb-monodromy", [&](ContinuationPoint* p) { return TryHarmonic(problem, p); });
  if (HillApplies() && unknowns_ <= options_.max_cross_check_unknowns)
    attempt("Hill", [&](ContinuationPoint* p) { return TryHill(problem, p); });
  if (!monodromy_refused_) attempt("monodromy", [&](ContinuationPoint* p) { return TryMonodromy(p); });
  if (tried.empty()) return false;
  // The rule's pick: the linearisation's monodromy, else Hill when cheap,
  // else the model's monodromy (the first in `tried` that qualifies).
  size_t pick = 0;
  if (tried[0].point.stability_method == StabilityMethod::kHill && unknowns_ > options_.max_hill_unknowns &&
      tried.size() > 1)
    pick = 1;
  *point = tried[pick].point;
  *done = true;
  for (size_t i = 0; i < tried.size(); ++i) {
    if (i == pick) continue;
    const StabilityMethod m = tried[i].point.stability_method;
    --(m == StabilityMethod::kHill ? hill_points_ : m == StabilityMethod::kMonodromy ? monodromy_points_ : harmonic_points_);
  }
  if (tried.size() < 2) return false;
  compared_ = true;
  std::string text;
  char part[200];
  for (const Tried& t : tried) {
    std::snprintf(part, sizeof part, "%s%s %.3g ms", text.empty() ? "" : ", ", t.name, 1e3 * t.seconds);
    text += part;
  }
  text += " at the first point; multipliers agree to";
  for (size_t i = 0; i < tried.size(); ++i)
    for (size_t j = i + 1; j < tried.size(); ++j) {
      std::snprintf(part, sizeof part, "%s %.1e (%s-%s)", i + j > 1 ? "," : "",
                    MatchedDifference(tried[i].point.multipliers, tried[i].point.trivial_multiplier,
                                      tried[j].point.multipliers, tried[j].point.trivial_multiplier),
                    tried[i].name, tried[j].name);
      text += part;
    }
  cross_check_ = text;
  return true;
}

bool BranchStability::TryHarmonic(const HarmonicBalanceProblem& problem, ContinuationPoint* point) {
  // From the grid the previous point suggested: one pass, not a sizing one.
  HarmonicMonodromyOptions options = options_.harmonic_monodromy;
  if (options.initial_samples == 0) options.initial_samples = harmonic_samples_;
  const MonodromyResult r = HarmonicMonodromy(problem, point->solution, options, &harmonic_samples_);
  if (!r.ok) {
    // Out of its scope (auxiliaries, a DAE) the same at every point; an
    // extrapolation that did not settle is left to the other methods too.
    harmonic_refused_ = true;
    note_ = "hb-monodromy: " + r.message;
    return false;
  }
  Finish(r.multipliers, r.trivial, StabilityMethod::kHarmonicMonodromy, point);
  ++harmonic_points_;
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
  for (size_t i = 0; i < order.size(); ++i) {
    p->multipliers.push_back(multipliers[order[i]]);
    if (order[i] == trivial) p->trivial_multiplier = static_cast<int>(i);
  }
  p->stability_method = method;
  const double band = NeutralBand(p->solution, options_.neutral_band);
  p->neutral_band = band;
  p->max_multiplier = JudgedModulus(multipliers, trivial, band);
  p->stability = p->max_multiplier < 1 - band   ? PointStability::kStable
                 : p->max_multiplier > 1 + band ? PointStability::kUnstable
                                                : PointStability::kNeutral;
  const double period = 2 * M_PI / p->solution.frequencies()[0];
  p->max_real_part = p->max_multiplier > 0 ? std::log(p->max_multiplier) / period : -HUGE_VAL;
}

}  // namespace rmhb

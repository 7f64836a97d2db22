#include "rmhb/sweep/sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "rmhb/monte_carlo.h"

namespace rmhb::sweep {
namespace {

// Starts of one point, in the order SolvePoint tries them.
struct Attempt {
  HarmonicSolution start;
  std::string route;
};

// The problem at `values`, and the starts' common basis.
struct PointProblem {
  HarmonicBalanceProblem problem;
  HarmonicBasis basis;
};

PointProblem MakePointProblem(const SweepModel& model, const std::vector<double>& values,
                              const SweepOptions& options) {
  HarmonicBalanceProblem problem = model.build(values);
  HarmonicBasis basis = MakeBasis(static_cast<int>(problem.frequencies.size()), options.solve);
  return {std::move(problem), std::move(basis)};
}

// A solve from a start already at the sweep's order: no order continuation.
HarmonicBalanceSummary SolveFrom(const HarmonicBalanceProblem& problem, const HarmonicSolution& start,
                                 const SweepOptions& options) {
  HarmonicBalanceOptions solve = options.solve;
  solve.order_continuation = false;
  return SolveHarmonicBalance(problem, start, solve);
}

// The previous point's solution carried to this point's first parameter in
// `substeps` natural-continuation steps; nullopt when a step fails.
std::optional<HarmonicBalanceSummary> Continue(const SweepModel& model, const PointResult& previous,
                                               const FoundSolution& from, const std::vector<double>& values,
                                               int substeps, const SweepOptions& options) {
  HarmonicSolution start = from.solution;
  for (int s = 1; s <= substeps; ++s) {
    std::vector<double> at = values;
    at[0] = s == substeps ? values[0]
                          : previous.values[0] + (values[0] - previous.values[0]) * s / substeps;
    HarmonicBalanceSummary summary = SolveFrom(model.build(at), start, options);
    if (!summary.usable()) return std::nullopt;
    if (s == substeps) return summary;
    start = *summary.solution;
  }
  return std::nullopt;
}

void Stability(const HarmonicBalanceProblem& problem, const SweepOptions& options, FoundSolution* found) {
  const HarmonicSolution& s = found->solution;
  if (!options.stability || s.frequencies().size() != 1) return;
  if (s.num_variables() * s.basis().num_coefficients() > options.max_stability_unknowns) return;
  try {
    const HillStabilityReport hill = HillStability(problem, s, options.hill);
    found->max_real_part = hill.max_real_part;
    const double band = options.hill.margin * s.frequencies()[0];
    found->stability = hill.stable ? "stable" : hill.max_real_part > band ? "unstable" : "neutral";
  } catch (const std::exception&) {
    // Outside Hill's scope (a pinned auxiliary): stays "unknown".
  }
}

// Adds a converged, physical solve unless it is one already found.
void Keep(const HarmonicBalanceSummary& summary, const std::string& route, const SweepOptions& options,
          PointResult* result) {
  const HarmonicSolution& s = *summary.solution;
  for (const FoundSolution& f : result->solutions)
    if (SolutionDifference(f.solution, s) < options.cluster_tolerance) return;
  result->solutions.push_back(FoundSolution{s, s.Amplitude(0), summary.solver.final_residual, route, "unknown", 0});
}

void TryStart(const HarmonicBalanceProblem& problem, const Attempt& attempt, const SweepOptions& options,
              PointResult* result) {
  ++result->solves;
  const HarmonicBalanceSummary summary = SolveFrom(problem, attempt.start, options);
  if (summary.usable())
    Keep(summary, attempt.route, options, result);
  else if (summary.converged())
    ++result->non_physical;
}

void SolveAtPoint(const SweepModel& model, const PointResult* previous, const SweepOptions& options,
                  PointResult* result) {
  const PointProblem point = MakePointProblem(model, result->values, options);
  const HarmonicBalanceProblem& problem = point.problem;
  if (previous != nullptr)
    for (const FoundSolution& from : previous->solutions) {
      for (int substeps = 1; substeps <= options.max_substeps; substeps *= 2) {
        ++result->solves;
        const auto summary = Continue(model, *previous, from, result->values, substeps, options);
        if (!summary) continue;
        Keep(*summary, substeps == 1 ? "continued" : "substeps " + std::to_string(substeps), options, result);
        break;
      }
    }
  const std::vector<Variable>& variables = problem.system.variables();
  if (model.guess)
    TryStart(problem, {model.guess(problem, options.solve.order).OnBasis(point.basis), "guess"}, options, result);
  // From rest: Newton's first step from zero is the linear response, so a
  // forced system lands on its small-amplitude branch, which random O(1)
  // starts tend to miss. (An autonomous one finds its equilibrium: rejected.)
  const Eigen::MatrixXd rest = Eigen::MatrixXd::Zero(static_cast<long>(variables.size()), point.basis.num_coefficients());
  TryStart(problem, {HarmonicSolution(point.basis, problem.frequencies, rest, variables), "rest"}, options, result);
  // Random mean and first harmonics only: random high harmonics of O(1)
  // are a violent signal from which Newton rarely finds anything.
  const HarmonicBasis first = HarmonicBasis::Diamond(point.basis.num_bases(), 1);
  for (int s = 0; s < options.starts; ++s) {
    const long draw = result->index * options.starts + s;
    const Eigen::MatrixXd c = RandomStart(options.seed, draw, static_cast<int>(variables.size()),
                                          first.num_coefficients(), options.low, options.high);
    const HarmonicSolution start = HarmonicSolution(first, problem.frequencies, c, variables).OnBasis(point.basis);
    TryStart(problem, {start, "start " + std::to_string(s)}, options, result);
  }
  std::stable_sort(result->solutions.begin(), result->solutions.end(),
                   [](const FoundSolution& a, const FoundSolution& b) { return a.amplitude < b.amplitude; });
  for (FoundSolution& f : result->solutions) Stability(problem, options, &f);
}

}  // namespace

const char* ToString(PointStatus status) {
  switch (status) {
    case PointStatus::kSolved: return "solved";
    case PointStatus::kNoSolution: return "no_solution";
    case PointStatus::kFailed: return "failed";
  }
  return "failed";
}

PointStatus PointStatusFromString(const std::string& text) {
  for (PointStatus s : {PointStatus::kSolved, PointStatus::kNoSolution, PointStatus::kFailed})
    if (text == ToString(s)) return s;
  throw std::invalid_argument("unknown point status '" + text + "'");
}

std::string SweepOptions::IsValid() const {
  if (starts < 0) return "starts must be >= 0";
  if (!(low < high) || !std::isfinite(low) || !std::isfinite(high)) return "the start range needs low < high";
  if (!(cluster_tolerance > 0)) return "cluster_tolerance must be > 0";
  if (max_substeps < 1) return "max_substeps must be >= 1";
  return solve.IsValid();
}

PointResult SolvePoint(const SweepModel& model, const ParameterGrid& grid, long index,
                       const PointResult* previous, const SweepOptions& options) {
  const auto begin = std::chrono::steady_clock::now();
  if (const std::string error = options.IsValid(); !error.empty())
    throw std::invalid_argument("sweep options: " + error);
  PointResult result;
  result.index = index;
  result.values = grid.Values(index);
  if (previous != nullptr && previous->status == PointStatus::kFailed) previous = nullptr;
  try {
    SolveAtPoint(model, previous, options, &result);
    result.status = result.solutions.empty() ? PointStatus::kNoSolution : PointStatus::kSolved;
    if (result.solutions.empty())
      result.message = "none of " + std::to_string(result.solves) + " solves converged to a physical solution (" +
                       std::to_string(result.non_physical) + " non-physical)";
  } catch (const std::exception& e) {
    result.status = PointStatus::kFailed;
    result.solutions.clear();
    result.message = e.what();
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return result;
}

}  // namespace rmhb::sweep

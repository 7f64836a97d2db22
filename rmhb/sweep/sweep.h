#ifndef RMHB_SWEEP_SWEEP_H_
#define RMHB_SWEEP_SWEEP_H_

// One point of a parameter sweep: every distinct steady state found there.
//   PointResult r = SolvePoint(model, grid, index, &previous_point, options);
// The solutions come, in this order, from
//  1. continuation of each solution of the previous point of the line (the
//     same point with the first parameter one step back): the previous
//     solution as the start, and if Newton does not converge from it, the
//     step cut into 2, 4, 8 natural-continuation substeps;
//  2. the model's own start, if it has one, and rest (all coefficients 0:
//     Newton's first step is the linear response);
//  3. K random starts (the mean and first harmonics uniform in [low, high]),
//     start s of point i drawn from a generator seeded by (seed, i K + s)
//     alone (RandomStart, rmhb/monte_carlo.h).
// Converged solves that the physical check rejects (an auxiliary off its
// definition, w <= 0) are counted, not kept; the rest are clustered (two are
// one when SolutionDifference < cluster_tolerance) and sorted by increasing
// amplitude. Each gets Hill's stability verdict when it applies.
//
// Deterministic: the result is a pure function of (model, grid, index,
// previous point's result, options), which is what makes a sweep's file
// independent of how many processes computed it and of interruptions
// (rmhb/sweep/run.h). A point that throws (a parameter outside the model's
// domain) is a result with status kFailed and the message, never an abort.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rmhb/harmonic_balance.h"
#include "rmhb/hill_stability.h"
#include "rmhb/sweep/parameter_grid.h"

namespace rmhb::sweep {

struct SweepModel {
  // The problem at the grid's parameter values (in axis order). May throw
  // std::invalid_argument for values outside the model's domain.
  std::function<HarmonicBalanceProblem(const std::vector<double>& values)> build;
  // The model's own start at an order, if it has one (e.g. its `guess`).
  std::function<HarmonicSolution(const HarmonicBalanceProblem& problem, int order)> guess;
};

struct SweepOptions {
  HarmonicBalanceOptions solve;  // order, sampling rule, solver
  int starts = 8;                // random starts per point
  double low = -2, high = 2;     // range of each random coefficient
  std::uint64_t seed = 1;
  double cluster_tolerance = 1e-6;
  int max_substeps = 8;          // continuation: 2, 4, ... up to this many
  bool stability = true;
  int max_stability_unknowns = 400;  // Hill's QZ is O(n^3): skipped above
  HillOptions hill;
  std::string IsValid() const;   // empty when valid
};

struct FoundSolution {
  HarmonicSolution solution;
  double amplitude = 0;   // max |z_0(t)| of the first variable
  double residual = 0;    // max |F| at convergence
  std::string route;      // "continued", "substeps 4", "guess", "rest", "start 3"
  std::string stability = "unknown";  // stable, unstable, neutral, unknown
  double max_real_part = 0;           // Hill: of the non-trivial exponents
};

enum class PointStatus {
  kSolved,      // at least one solution
  kNoSolution,  // every start failed or was non-physical
  kFailed,      // the point could not be set up (message says why)
};
const char* ToString(PointStatus status);  // "solved", "no_solution", "failed"
PointStatus PointStatusFromString(const std::string& text);  // throws for others

struct PointResult {
  long index = -1;
  std::vector<double> values;
  PointStatus status = PointStatus::kFailed;
  std::string message;
  std::vector<FoundSolution> solutions;  // distinct, by increasing amplitude
  int solves = 0;         // Newton solves started
  int non_physical = 0;   // converged solves rejected by the physical check
  double seconds = 0;     // wall clock; in the log, not in the sweep's file
};

PointResult SolvePoint(const SweepModel& model, const ParameterGrid& grid, long index,
                       const PointResult* previous, const SweepOptions& options);

}  // namespace rmhb::sweep

#endif  // RMHB_SWEEP_SWEEP_H_

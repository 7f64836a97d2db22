#ifndef RMHB_MONTE_CARLO_H_
#define RMHB_MONTE_CARLO_H_

// Many random starts, every distinct solution they reach, and what each one
// is: the experiment of the paper's Table 1 (METHOD.md s.3). Every harmonic
// coefficient of every variable of a start is drawn uniformly from a range;
// each start is solved with each sampling rule (RHB, HDHB, ...) at the same
// order; the converged solutions are clustered, and each cluster classified:
//  - physical: a much higher-order alias-free solve started from it converges
//    to a physical solution (HarmonicBalanceSummary::physical, the definition
//    check of rmhb/definition_check.h when the problem has auxiliaries) whose
//    first harmonics it matches (relative distance below match_tolerance) --
//    it approximates a true periodic solution;
//  - non-physical otherwise (aliasing: HDHB below Theorem 1's bound);
// and a physical one as stable or unstable by Hill's method on that
// high-order solution (rmhb/hill_stability.h), optionally confirmed by a
// check on the original equations the caller supplies (the CLI passes
// Floquet multipliers of a CVODE integration, integrators/floquet.h).
//
// Deterministic: start i draws from a generator seeded by (seed, i) alone,
// and results are gathered by start index, so the census does not depend on
// the number of threads.

#include <complex>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "rmhb/harmonic_balance.h"
#include "rmhb/hill_stability.h"

namespace rmhb {

enum class SolutionClass { kPhysicalStable, kPhysicalUnstable, kNonPhysical };
const char* ToString(SolutionClass c);  // "physical-stable", ...

// A verdict from outside the harmonic balance, on the original equations.
struct OriginalCheck {
  bool ok = false;  // the check ran (e.g. the integration succeeded)
  bool stable = false;
  std::vector<std::complex<double>> multipliers;
  double closure_error = 0;  // max|y(T) - y(0)| of the integrated orbit
  std::string message;
};

struct MonteCarloOptions {
  long starts = 10000;
  // Every unknown coefficient uniform in [low, high]. With
  // solve.condense_definitions (the default) a variable defined by a linear
  // x' = v is no unknown, its coefficients follow from x's: the Duffing's
  // 2N + 1 unknowns of the second-order form, as classical HB writes it (with
  // them HDHB finds 58-59 distinct solutions, 55-56 non-physical; the paper
  // 58 and 55).
  double low = -2, high = 2;
  std::uint64_t seed = 1;
  int threads = 0;  // 0: std::thread::hardware_concurrency()
  std::vector<SamplingRule> rules = {SamplingRule::kRhb, SamplingRule::kHdhb};
  // Order, solver options; the rule is set per entry of `rules`.
  HarmonicBalanceOptions solve;
  // SolverOptions::newton_stall_iterations for the starts (when the solver's
  // own is 0): a Newton run caught in a cycle hands over to the Levenberg-
  // Marquardt fallback, which starts from the start itself, after this many
  // iterations without halving max|F| instead of after max_iterations.
  // Converging Newton runs of the Duffing census (10^4 starts, both rules)
  // went up to 29 iterations without halving; at 20 the few cut short are
  // handed to the fallback sooner, which converged all but 3 (RHB, seed 1;
  // 1 with seed 2) to the same solution: the shares move by 0.04 %, a tenth
  // of the census's sampling error (~0.4 %), while RHB's solves cost 10-15 %
  // less than at 40 (and ~40 % less than without the test).
  int newton_stall_iterations = 20;
  // Order of the alias-free reference solves; 0: max(40, 8 * order).
  int reference_order = 0;
  // Two converged starts are one solution when their coefficients differ by
  // less than this, relative to the larger coefficient (at least 1).
  double cluster_tolerance = 1e-6;
  // A cluster is physical when it is this close (max coefficient difference
  // over its harmonics, relative to the reference's largest coefficient) to
  // the reference solve started from it: truncation and aliasing errors of
  // physical low-order solutions are well below it, non-physical solutions are
  // O(1) away. The distance is reported, so the margin can be seen.
  double match_tolerance = 0.05;
  // Called with (starts done, total) from the worker threads, serialised.
  std::function<void(long done, long total)> progress;
  // Optional second opinion on each physical reference solution; called from
  // the worker threads, concurrently.
  std::function<OriginalCheck(const HarmonicSolution&)> original_check;

  std::string IsValid() const;  // empty when valid
};

struct SolutionCluster {
  explicit SolutionCluster(HarmonicSolution first) : representative(std::move(first)) {}
  HarmonicSolution representative;  // the first start (lowest index) that reached it
  long count = 0;
  double share = 0;                 // percent of this rule's converged starts
  double amplitude = 0;             // max |z_0(t)| of the first variable
  SolutionClass solution_class = SolutionClass::kNonPhysical;
  // Relative distance to the reference solve from it; +inf if that failed.
  double reference_distance = 0;
  std::optional<HarmonicSolution> reference;  // when physical
  std::optional<HillStabilityReport> hill;    // when physical
  std::optional<OriginalCheck> original;      // when physical and a check was given
};

struct RuleCensus {
  SamplingRule rule = SamplingRule::kRhb;
  int samples = 0;
  int alias_free_samples = 0;
  long converged = 0;
  long failed = 0;                  // starts that did not converge (or reached w <= 0)
  std::vector<SolutionCluster> clusters;  // by decreasing count
  int non_physical_clusters() const;
  double share(SolutionClass c) const;  // percent of converged starts
  double solve_seconds = 0;             // CPU seconds of the solves, all threads together
};

struct MonteCarloSummary {
  std::vector<RuleCensus> rules;
  long starts = 0;
  int order = 0;
  int reference_order = 0;
  int threads = 0;
  double seconds = 0;  // wall clock, everything

  std::string BriefReport() const;
  std::string FullReport() const;  // the Table-1 style table
};

// Throws std::invalid_argument for invalid options or a problem the census
// cannot classify: quasi-periodic, autonomous (unknown frequency), or with
// pinned recast auxiliaries (Hill's method does not apply).
MonteCarloSummary RunMonteCarlo(const HarmonicBalanceProblem& problem,
                                const MonteCarloOptions& options);

// The census in two steps, for running its starts on several processes
// (MPI, rmhb/sweep/monte_carlo_mpi.h): each solves its share of the starts,
// the root gathers every outcome and takes the census. RunMonteCarlo is
// CensusOfStarts(SolveStarts(...)); the census depends on the outcomes by
// start index only, so it is the same however the starts were shared out.
struct StartOutcome {
  Eigen::MatrixXd coefficients;     // empty: the start did not converge (or w <= 0)
  std::vector<double> frequencies;  // as solved
};
struct StartSolves {
  std::vector<std::vector<StartOutcome>> outcomes;  // [rule][start], all options.starts
  std::vector<double> rule_seconds;                 // CPU seconds per rule, this process
  int threads = 1;
};
// Solves starts first, first + stride, ... below options.starts (the others
// stay empty). Throws like RunMonteCarlo.
StartSolves SolveStarts(const HarmonicBalanceProblem& problem, const MonteCarloOptions& options,
                        long first = 0, long stride = 1);
MonteCarloSummary CensusOfStarts(const HarmonicBalanceProblem& problem, const MonteCarloOptions& options,
                                 const StartSolves& solves);

// The coefficients of start `index`: a pure function of (seed, index).
Eigen::MatrixXd RandomStart(std::uint64_t seed, long index, int variables, int coefficients,
                            double low, double high);

}  // namespace rmhb

#endif  // RMHB_MONTE_CARLO_H_

#ifndef RMHB_HARMONIC_BALANCE_H_
#define RMHB_HARMONIC_BALANCE_H_

// The library's front door:
//   HarmonicBalanceSummary s = SolveHarmonicBalance(problem, guess, options);
// picks the basis, the sampling (RHB alias-free by default, or HDHB / AFT),
// solves, and returns the solution with a report. Non-convergence is a
// status in the summary; misuse (bad options, malformed problem) throws
// std::invalid_argument with a message saying what is wrong.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "rmhb/definition_check.h"
#include "rmhb/harmonic_balance_problem.h"
#include "rmhb/harmonic_basis.h"
#include "rmhb/harmonic_solution.h"
#include "rmhb/nonlinear_solver.h"
#include "rmhb/sampling.h"

namespace rmhb {

// kAdaptive (several bases, with a tolerance): start from the diamond of
// `order` and the guess's harmonics, then add the neighbours of every
// coefficient above the tolerance until the truncation estimate meets it
// (METHOD.md s.8); without a tolerance, the diamond.
enum class BasisShape { kDiamond, kBox, kAdaptive };

// What an accuracy target bounds: the time-domain solution (every variable,
// relative to its largest coefficient) or the unknown base frequencies
// (relative), which converge faster (METHOD.md s.8).
enum class TargetQuantity { kState, kFrequency };
const char* ToString(TargetQuantity quantity);  // "state", "frequency"
// Throws std::invalid_argument for another name.
TargetQuantity ParseTargetQuantity(const std::string& name);

// Quasi-periodic sampling (METHOD.md s.6). Both are the same projection when
// alias-free; the torus grid costs prod_i M_i with M_i > (phi+1)p whatever
// the frequencies, the GCD rule (Theorem 2) needs M > (phi+1) p max(r_i) over
// one period 2 pi / gcd(w), huge for close or nearly irrational frequencies.
enum class QuasiPeriodicSampling { kTorus, kGcd };

// Piecewise-smooth pointwise equations (METHOD.md s.15) fold their
// algebraically decaying spectrum onto the kept harmonics at any grid: on
// the finer grid the residual of a true solution is the quadrature error of
// the kinks (~1e-5 at M = 64 N for a unilateral spring of stiffness 100),
// while a solution that exists only at the samples leaves O(1). So their
// alias check fails only above this (relative) bound.
constexpr double kNonSmoothAliasFloor = 1e-2;

struct HarmonicBalanceOptions {
  int order = 10;  // N for one base, p for several
  BasisShape shape = BasisShape::kDiamond;
  // When set, the basis of order p for several bases, instead of `shape`: a
  // problem-specific index set (HarmonicBasis::FromHarmonics) such as the
  // fast/slow rectangle of a beating torus. Examples that need one provide
  // it (examples::ExampleSetup::basis_for_order). Order continuation calls it
  // at the lower orders too.
  std::function<HarmonicBasis(int order)> basis_for_order;
  SamplingRule rule = SamplingRule::kRhb;
  // Explicit samples per base (overrides the rule). Below the alias-free
  // count this is refused unless allow_aliasing is set: aliasing creates
  // non-physical solutions (METHOD.md s.2).
  std::vector<int> samples;
  bool allow_aliasing = false;
  QuasiPeriodicSampling quasi_periodic_sampling = QuasiPeriodicSampling::kTorus;
  double gcd_tolerance = 1e-12;   // relative, for the rational approximation of w_i/w_1
  // The GCD rule is refused (std::invalid_argument naming both sample
  // counts) when it needs more than this many times the samples of the torus
  // grid for the same basis. Close base frequencies make the period
  // 2 pi / gcd(w) huge: 0.9857 : 0.9935 = 9857 : 9935 needs ~2e5 samples at
  // p = 5 where the torus grid needs 21 x 21, and a ratio known only to
  // round-off (unknown frequencies) needs even more.
  double max_gcd_excess = 16;
  long max_samples = 20'000'000;  // refuse larger grids up front (memory)
  // Refuse up front (std::invalid_argument naming the size) an order whose
  // dense Jacobian, residual rows x unknowns doubles before condensation,
  // would need more than this: a clear error instead of std::bad_alloc, an
  // OOM kill or an hour-long LU. Order selection stops at the largest order
  // under it. 4 GiB is about 23000 unknowns, minutes per factorisation.
  double max_jacobian_bytes = 4.0 * (1L << 30);
  // Solve at lower orders first (N/4, N/2, ...) and warm-start: a high-order
  // solve then needs one or two iterations of the large system.
  bool order_continuation = true;
  // Eliminate variables defined by a linear equation c1 a' + c2 b = 0 (the
  // recast's x' = v) and their rows (CollocationResidual): the same discrete
  // solution with half the unknowns of a second-order oscillator (with
  // symmetries too: they then act on the condensed unknowns).
  bool condense_definitions = true;
  // Automatic order selection when > 0 (METHOD.md s.8): solve at `order`,
  // estimate the truncation error from the coefficient tail
  // (EstimateTruncation, rmhb/truncation_estimate.h, calibrated on a lower
  // order), and raise the order in small steps, warm-started, until the
  // estimate of `tolerance_quantity` is within `tolerance`. The summary
  // holds the estimates per quantity. Not reached by max_order:
  // kNoConvergence. rmhb's studies set 1e-10 unless the user fixes the order.
  double tolerance = 0;
  TargetQuantity tolerance_quantity = TargetQuantity::kState;
  // A target the user did not ask for (rmhb's default): not reaching it by
  // max_order (for the adaptive index set: the reach max |k|_1) leaves the
  // solve converged, with the estimate and why in the message.
  bool soft_tolerance = false;
  // Order selection: when the solve at `order` fails, try 2x, 4x, 8x it
  // from the same guess before giving up (too low an order can have no
  // solution near the physical one: the pendulum near its separatrix).
  bool raise_order_on_failure = true;
  int max_order = 5000;
  SolverOptions solver;
  // After a converged solve: is it an oscillation of the original equations?
  // An unknown base frequency at or below min_frequency_ratio times its
  // guess (w = 0 is a constant, not an oscillation), an equilibrium found
  // with an unknown frequency (every harmonic but the mean below 1e-10 of
  // the largest coefficient: w is undetermined) and, when the problem
  // has definitions, auxiliaries that disagree with them (a wrong root of
  // the recast, aliasing) make it non-physical.
  bool check_physical = true;
  double min_frequency_ratio = 1e-3;
  DefinitionCheckOptions definition_check;

  std::string IsValid() const;  // empty when valid
};

struct HarmonicBalanceSummary {
  SolverSummary solver;
  std::optional<HarmonicSolution> solution;
  std::string sampling;             // description of the grid used
  std::vector<int> samples;         // per base
  std::vector<int> alias_free_samples;
  bool alias_free = true;
  int degree = 0;                   // phi
  int order = 0;
  SamplingRule rule = SamplingRule::kRhb;
  double seconds = 0;
  // Order selection (options.tolerance > 0): the orders solved in turn, the
  // target, and the estimated errors of the returned solution (-1 when not
  // selected): of the targeted quantity, of the time-domain solution and of
  // the unknown frequencies (-1 without any), and whether a lower order
  // calibrated them (EstimateTruncation).
  std::vector<int> orders_tried;
  double tolerance = 0;
  TargetQuantity tolerance_quantity = TargetQuantity::kState;
  double truncation_estimate = -1;
  double state_estimate = -1, frequency_estimate = -1;
  bool estimate_calibrated = false;
  // A non-smooth model's quadrature error, included in the estimates above:
  // the difference from the solution on half the samples (-1: not measured).
  double sampling_estimate = -1;
  // Order selection stopped short of the tolerance after a converged solve
  // (the status then says not converged unless options.soft_tolerance): the
  // solution is good to the estimates, another start would not change them.
  bool short_of_target = false;
  // Symmetries of the equations that order selection or the adaptive index
  // set found in its first converged solution (to 1e-11) and imposed from
  // then on, and those a settled forced record had to 1e-9, imposed on the
  // whole solve (Analyze); continuation keeps imposing them along the branch.
  std::vector<HalfTurnSymmetry> symmetries_found;
  // Set after a converged solve (options.check_physical): the algebra
  // converged (solver.status) but the solution is not an oscillation of the
  // original equations; `non_physical` says why (which frequency or
  // auxiliary). The definition check, when the problem has definitions.
  bool physical = true;
  std::string non_physical;
  // > 1: the solution repeats that many times per period (non-physical: its
  // one unknown frequency is a sub-multiple of the orbit's;
  // HarmonicSolution::OnMultipleFrequency restates it).
  int repeats = 1;
  std::optional<DefinitionCheck> definition_check;
  // Pointwise (original) equations only: max|F| on a grid twice as fine,
  // relative to max(1, max|coefficient|), and that grid (-1, empty: not run).
  double alias_residual = -1;
  std::vector<int> alias_check_samples;
  // The bound alias_residual was judged against: definition_check.floor, or
  // kNonSmoothAliasFloor for piecewise-smooth equations.
  double alias_tolerance = 0;

  bool converged() const { return solver.converged(); }
  // Converged and physical: the solution can be used.
  bool usable() const { return converged() && physical; }
  std::string BriefReport() const;
  std::string FullReport() const;
};

HarmonicBalanceSummary SolveHarmonicBalance(const HarmonicBalanceProblem& problem,
                                            const HarmonicSolution& initial_guess,
                                            const HarmonicBalanceOptions& options);

// Largest change between two solutions of one problem at different orders,
// as order selection measures it (see HarmonicBalanceOptions::tolerance).
double SolutionDifference(const HarmonicSolution& a, const HarmonicSolution& b);

// Rows and columns of the dense Jacobian at options.order (before
// condensation and symmetries, which only shrink it), counted without
// building the basis when it has a closed form.
struct JacobianSize {
  double rows = 0, columns = 0;
  double bytes() const { return 8 * rows * columns; }
};
JacobianSize DenseJacobianSize(const HarmonicBalanceProblem& problem,
                               const HarmonicBalanceOptions& options);
// Throws std::invalid_argument ("order N needs a dense Jacobian of R x C
// doubles (X GiB); the limit is Y GiB ...") above options.max_jacobian_bytes.
// SolveHarmonicBalance calls it; callers that build a guess at the order
// first (a simulation, a random start) call it before.
void CheckJacobianSize(const HarmonicBalanceProblem& problem, const HarmonicBalanceOptions& options);

// The basis the options describe for `num_bases` base frequencies.
HarmonicBasis MakeBasis(int num_bases, const HarmonicBalanceOptions& options);

}  // namespace rmhb

#endif  // RMHB_HARMONIC_BALANCE_H_

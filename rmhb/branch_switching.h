#ifndef RMHB_BRANCH_SWITCHING_H_
#define RMHB_BRANCH_SWITCHING_H_

// Branch switching at the bifurcations TraceBranch locates
// (rmhb/continuation.h, rmhb/bifurcation.h; METHOD.md s.14):
//
//  - Period doubling: the branch of period 2T. The problem is rewritten on
//    the base w/2 (PeriodMultiplied: a forcing harmonic k becomes 2k). There
//    the period-T branch lives on the even harmonics, and at the PD point the
//    Jacobian has a null vector on the odd ones: the critical Floquet mode
//    e^{i w t/2} p(t), p T-periodic. In the doubled problem the new branch
//    crosses the old one there (a pitchfork: x(t) -> x(t + T) maps one half
//    onto the other), so the trace starts at the PD point along that mode
//    (TraceBranchFrom) and follows the period-2T branch over the range.
//
//  - Neimark-Sacker: the torus. The problem is put on two bases, the
//    forcing's w and w2 = w arg(mu) / (2 pi) from the critical multiplier mu
//    (WithSecondBase). The periodic orbit, embedded on the (k, 0) harmonics,
//    solves it for any w2, and at the NS point the Jacobian with w2 fixed is
//    singular on the (k, +-1) harmonics: the critical mode e^{i w2 t} p(t).
//    A corrector in (x, w2, lambda) with the integral phase condition
//    <x, d v / d theta2> = 0 (which fixes the free phase of theta2; Schilder,
//    Vogt, Schreiber, Osinga 2005) and the amplitude condition
//    <x - x_ns, v> = epsilon finds the torus of size epsilon next to the NS
//    point; the parameter value is part of the answer (just past the NS
//    point: lambda - lambda_ns ~ epsilon^2). The result carries what torus
//    continuation needs to go on from there: the two-base problem, its basis
//    and sampling, the solution and the phase reference.
//
// Both find the critical mode by inverse iteration on the harmonic balance
// Jacobian of the extended problem at the located point, restricted to the
// new harmonics; its residual |J v| / |J| says how singular the located
// point really is.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "rmhb/continuation.h"
#include "rmhb/sampling.h"

namespace rmhb {

// The problem with base w / factor: every forcing harmonic k becomes
// factor k (cos(k w t) = cos(factor k (w / factor) t)); conditions at t = 0
// unchanged, asserted symmetries dropped (a half-period shift of the old
// period is not one of the new), definitions evaluated on the old angle.
HarmonicBalanceProblem PeriodMultiplied(const HarmonicBalanceProblem& problem, int factor);
// The same function of time on the base w / factor: harmonic k becomes
// factor k (basis Periodic(factor N)).
HarmonicSolution PeriodMultipliedSolution(const HarmonicSolution& solution, int factor);

// The problem on one base w = w_1 / a_1 when every base is a multiple of it,
// w_b = a_b w (a torus locked at w_2 / w_1 = a_2 / a_1): a time function's
// harmonic k becomes sum_b a_b k_b; the first base's known/unknown status
// is kept, conditions are kept (the caller drops those that fixed the lost
// angles), asserted symmetries dropped, definitions evaluated on the old
// angles a_b theta.
HarmonicBalanceProblem OnResonantBase(const HarmonicBalanceProblem& problem, const std::vector<int>& multiples);

struct DoubledBranch {
  bool started = false;
  std::string message;   // why not, or how it ended
  double critical_mode_residual = 0;  // |J v|_inf / |J|_inf of the PD mode on the odd harmonics
  std::optional<ContinuationSummary> branch;  // on the base w / 2 (order 2N)
};

// The period-2T branch from the located period doubling `pd` of `branch`
// (TraceBranch's summary on `problem`), continued over problem's range with
// `options` (the doubled basis has twice the branch's order). It stops
// (status kStopped) where it merges back into the period-T branch: where its
// odd harmonics pass through zero.
DoubledBranch TraceDoubledBranch(const ContinuationProblem& problem, const ContinuationSummary& branch,
                                 const BifurcationPoint& pd, const ContinuationOptions& options);

// The problem on two bases: the problem's own (known, or unknown as it was)
// and an unknown second one with guess w2; the forcing stays on the first.
HarmonicBalanceProblem WithSecondBase(const HarmonicBalanceProblem& problem, double w2);

struct TorusOptions {
  // Harmonics (k, l) of the torus basis: |k| <= order (0: the branch's
  // order) along the first base, |l| <= order_new along the new one.
  int order = 0;
  int order_new = 4;
  // The torus' size along theta2 at the start: epsilon = amplitude |x_ns|
  // (coefficient norms). Larger goes farther from the NS point.
  double amplitude = 0.02;
  int max_iterations = 40;
  std::string IsValid() const;
};

struct TorusStart {
  bool solved = false;
  std::string message;
  std::string parameter_name;
  double bifurcation_parameter = 0;  // the NS point
  double parameter = 0;              // where the torus was solved
  double w2_at_bifurcation = 0;      // w arg(mu) / (2 pi)
  // The torus (bases {w, w2}, w2 solved), its harmonic balance residual
  // max|F| and the size of its theta2 part (max over the variables of the
  // root-sum-square of the l != 0 coefficients).
  std::optional<HarmonicSolution> torus;
  double residual = 0;
  double theta2_amplitude = 0;
  // The same for the outermost harmonics |l| = order_new, relative to
  // theta2_amplitude: a truncation estimate along the new angle (raise
  // TorusOptions::order_new when it is not small).
  double theta2_tail = 0;
  // The periodic orbit next to the NS point on the torus' side: "stable"
  // (a subcritical NS: the torus is unstable) or "unstable" (supercritical).
  std::string periodic_side;
  double critical_mode_residual = 0;
  int iterations = 0;
  double seconds = 0;
  // For continuing the torus (torus continuation): the two-base problem at
  // `parameter` (w2 unknown), the basis and sampling the solution lives on,
  // and the phase reference: the phase condition is
  // <x, d(reference)/d theta2> = 0 on the coefficients.
  std::optional<HarmonicBalanceProblem> problem;
  std::optional<Sampling> sampling;
  std::optional<HarmonicSolution> phase_reference;

  std::string BriefReport() const;
};

// The torus born at the located Neimark-Sacker point `ns` of `branch`
// (TraceBranch's summary on `problem`). `options` gives the solver and
// sampling rule.
TorusStart TorusFromNeimarkSacker(const ContinuationProblem& problem, const ContinuationSummary& branch,
                                  const BifurcationPoint& ns, const ContinuationOptions& options,
                                  const TorusOptions& torus = {});

// The integral phase condition's row on a residual's unknowns: the
// coefficients of d(reference)/d theta_base, packed like the residual's
// unknowns (zero on the frequencies).
Eigen::RowVectorXd PhaseConditionRow(const CollocationResidual& residual, const HarmonicSolution& reference,
                                     int base);

}  // namespace rmhb

#endif  // RMHB_BRANCH_SWITCHING_H_

#ifndef RMHB_CONTINUATION_H_
#define RMHB_CONTINUATION_H_

// Parameter continuation: follow a branch of (quasi-)periodic harmonic
// balance solutions x(lambda) as a model parameter lambda moves from `start`
// to `end`:
//   ContinuationSummary s = TraceBranch(problem, guess, options);
//
//  - Natural-parameter continuation steps lambda and corrects x at the new,
//    fixed lambda from a secant predictor. Cheap, but it cannot pass a
//    turning point (fold), where dx/dlambda is infinite: the corrector fails
//    there and the trace stops, saying so.
//  - Pseudo-arclength continuation (Keller 1977; Allgower & Georg,
//    "Numerical Continuation Methods", ch. 2) makes lambda one more unknown
//    and steps along the unit tangent t of the branch in y = (x, lambda):
//    predictor y0 + ds t, corrector (Newton) on the bordered system
//        F(x, lambda) = 0,    t . (y - y0) = ds,
//    whose Jacobian [F_x F_lambda; t'] stays regular at a fold. A fold is
//    where the lambda component of t changes sign; it is then located by
//    regula falsi on that component along the arc.
// The step (arclength, or lambda for natural continuation) grows after a
// corrector that converges in a few iterations and halves after one that
// fails or turns the tangent too far (which is how a step jumps branches).
//
// lambda is any model parameter (a forcing frequency, a stiffness, the
// initial velocity in a point condition): ContinuationProblem::build makes
// the harmonic balance problem at each value, and dF/dlambda is a forward
// difference of the rebuilt residual. Its ~1e-8 relative error slows Newton
// only in its last digits and does not move the folds: at a fold F_x is
// singular and the tangent's lambda component is zero whatever F_lambda is.
//
// Misuse (invalid options, a build whose structure changes with lambda)
// throws std::invalid_argument; a branch that cannot be followed to `end`
// is a status in the summary, with the points found so far.

#include <functional>
#include <string>
#include <vector>

#include "rmhb/harmonic_balance.h"
#include "rmhb/hill_stability.h"

namespace rmhb {

struct ContinuationProblem {
  std::string parameter = "lambda";  // its name, for reports
  double start = 0;
  double end = 1;
  // The problem at a parameter value. It may throw std::invalid_argument
  // for a value outside the model's domain (that step then fails); every
  // value must give the same variables, equations, conditions, unknown
  // frequencies and symmetries.
  std::function<HarmonicBalanceProblem(double value)> build;
};

enum class ContinuationMethod { kNatural, kPseudoArclength };
const char* ToString(ContinuationMethod method);

struct ContinuationOptions {
  ContinuationMethod method = ContinuationMethod::kPseudoArclength;
  // Order, sampling rule and solver of the first solve; the correctors use
  // the same basis and samples with Newton.
  HarmonicBalanceOptions harmonic_balance;
  // Steps are arclength in (x, lambda), x the solver's unknowns (harmonic
  // coefficients, unknown frequencies), or lambda for natural continuation.
  // 0 picks a default from the range r = |end - start|: initial r/20, max
  // r/10, min 1e-7 r.
  double initial_step = 0;
  double max_step = 0;
  double min_step = 0;
  double step_growth = 1.5;
  double step_shrink = 0.5;
  int fast_iterations = 6;           // grow the step after at most this many
  int max_corrector_iterations = 15;
  // Largest angle (radians) between consecutive tangents; a larger turn is
  // refused and retried with a smaller step.
  double max_turn = 0.5;
  int max_points = 5000;
  double max_seconds = 0;            // 0: no limit (checked between steps)
  // Locate each fold to |d lambda / ds| <= fold_tolerance (pseudo-arclength).
  bool locate_folds = true;
  double fold_tolerance = 1e-9;
  // Stability of every point by Hill's method (rmhb/hill_stability.h): one
  // generalised eigenproblem (QZ, O(n^3) with a large constant) of the size
  // of the Jacobian per point, so it is skipped above max_stability_unknowns
  // (measured on the Duffing branch at 62 unknowns: ~3 ms per point, twice
  // the rest of the step; ~100 ms at 200). Outside its scope (quasi-periodic, pinned
  // auxiliaries) or after its eigensolver failed twice, points stay
  // kUnknown too; the summary says why.
  bool stability = true;
  int max_stability_unknowns = 200;
  HillOptions hill;

  std::string IsValid() const;       // empty when valid
};

enum class ContinuationStatus {
  kCompleted,     // reached `end`
  kLeftRange,     // the branch turned back and left through `start`
  kStepTooSmall,  // the corrector failed down to the minimum step
  kPointLimit,    // max_points reached
  kTimeLimit,     // max_seconds reached
  kStartFailed,   // no solution at `start`
};
const char* ToString(ContinuationStatus status);

enum class PointStability {
  kUnknown,   // not computed, or outside Hill's method's scope
  kStable,    // every non-trivial Floquet exponent has Re < -margin w
  kUnstable,  // one has Re > margin w
  kNeutral,   // the largest is within the margin: a fold, or a conservative system
};
const char* ToString(PointStability stability);

struct ContinuationPoint {
  double parameter = 0;
  HarmonicSolution solution;
  double residual = 0;          // max|F| of the harmonic balance equations here
  int iterations = 0;           // of the corrector
  double arclength = 0;         // from the first point, along the chords
  // d lambda / ds of the unit tangent (pseudo-arclength); 0 at a fold.
  // Natural continuation: the sign of the step.
  double tangent_parameter = 0;
  bool fold = false;            // a located turning point
  int folds_before = 0;         // folds passed from the start to here
  PointStability stability = PointStability::kUnknown;
  double max_real_part = 0;     // of the non-trivial Floquet exponents (Hill), if known
};

struct ContinuationSummary {
  ContinuationStatus status = ContinuationStatus::kStartFailed;
  ContinuationMethod method = ContinuationMethod::kPseudoArclength;
  std::string parameter;
  double start = 0, end = 0;   // the range asked for
  std::string message;
  std::string stability_note;  // why stability is unknown, if it is
  std::vector<ContinuationPoint> points;
  int accepted_steps = 0;
  int rejected_steps = 0;
  int corrector_iterations = 0;  // over all accepted and rejected steps
  int num_folds = 0;
  double arclength = 0;
  double seconds = 0;
  // Basis order and samples of every point.
  int order = 0;
  std::vector<int> samples;

  bool completed() const { return status == ContinuationStatus::kCompleted; }
  std::string BriefReport() const;
  std::string FullReport() const;  // adds one line per point
};

// `guess`: near the solution at `start`, on any basis.
ContinuationSummary TraceBranch(const ContinuationProblem& problem, const HarmonicSolution& guess,
                                const ContinuationOptions& options);

}  // namespace rmhb

#endif  // RMHB_CONTINUATION_H_

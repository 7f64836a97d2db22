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
// Every point gets its Floquet multipliers (stability) by Hill's method
// on the harmonic balance Jacobian where that is cheap and applies, else
// from the monodromy matrix of the original equations when the problem
// provides it (ContinuationProblem::monodromy; rmhb/pipeline/branch.h binds
// a model's CVODE monodromy): its cost does not depend on the harmonic
// order, so stability is known at every point whatever the size. Between
// two points a real multiplier through +1 (branch point; folds are found
// from the tangent), through -1 (period doubling) or a complex pair through
// the unit circle (Neimark-Sacker) is detected by the sign of a test
// function and located along the arc (rmhb/bifurcation.h, METHOD.md s.14).
// Branch switching from those points: rmhb/branch_switching.h.
//
// Misuse (invalid options, a build whose structure changes with lambda)
// throws std::invalid_argument; a branch that cannot be followed to `end`
// is a status in the summary, with the points found so far.

#include <complex>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "rmhb/bifurcation.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/harmonic_monodromy.h"
#include "rmhb/hill_stability.h"

namespace rmhb {

struct ContinuationPoint;

using MonodromyFunction =
    std::function<MonodromyResult(double value, const HarmonicSolution& solution, int period_multiple)>;

struct ContinuationProblem {
  std::string parameter = "lambda";  // its name, for reports
  double start = 0;
  double end = 1;
  // The problem at a parameter value. It may throw std::invalid_argument
  // for a value outside the model's domain (that step then fails); every
  // value must give the same variables, equations, conditions, unknown
  // frequencies and symmetries.
  std::function<HarmonicBalanceProblem(double value)> build;
  // Set when build(value) differs from build(start) in its base frequencies
  // alone (the model has proved it: Model::frequency_parameters, a forcing
  // frequency): the corrector's residuals are then built once and a new
  // value only sets their frequencies (METHOD.md s.19), instead of a new
  // residual at every value. A promise: nothing checks it.
  bool only_frequencies_change = false;
  // Optional: the multipliers of the original equations at a point (see
  // MonodromyResult). Without it stability comes from Hill's method alone.
  MonodromyFunction monodromy;
  // The base frequency of build()'s problem is this many periods of the
  // model's forcing: 2 on a period-doubled branch (rmhb/branch_switching.h).
  int period_multiple = 1;
  // Optional: a reason to stop after a point (empty: go on), e.g. a
  // period-doubled branch that merged back into the period-T branch.
  std::function<std::string(const ContinuationPoint& point)> stop_when;
};

enum class ContinuationMethod { kNatural, kPseudoArclength };
const char* ToString(ContinuationMethod method);

// How a point's Floquet multipliers are computed (kNone on a point: not at all).
// kHarmonicMonodromy: the monodromy of the harmonic balance linearisation
// integrated in the time domain (rmhb/harmonic_monodromy.h).
enum class StabilityMethod { kAuto, kHill, kMonodromy, kHarmonicMonodromy, kNone };
// "auto", "hill", "monodromy", "hb-monodromy", "none"
const char* ToString(StabilityMethod method);
// "auto", "hill", "monodromy", "hb-monodromy"; throws std::invalid_argument otherwise.
StabilityMethod ParseStabilityMethod(const std::string& name);

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
  // Stability of every point from its Floquet multipliers. kAuto: the
  // monodromy of the harmonic balance linearisation integrated in the time
  // domain (rmhb/harmonic_monodromy.h: its cost depends on the states and
  // not on the order; Hill's multipliers to ~1e-12) wherever it applies (a
  // periodic solution of an ODE without recast auxiliaries); elsewhere
  // Hill's method (rmhb/hill_stability.h: one generalised eigenproblem, QZ,
  // of the size n of the Jacobian, O(n^3)) up to max_hill_unknowns unknowns,
  // above that the monodromy of the original equations when the problem
  // provides it (ContinuationProblem::monodromy: its cost grows with the
  // number of states, not with the order), else Hill's method at any size.
  // Measured on the forced Duffing oscillator at N = 15 (62 unknowns): ~0.1-0.3
  // ms per point by the linearisation's monodromy, 2.7 ms by QZ, 0.5-1 ms by
  // CVODE at rtol 1e-10; a two-degree-of-freedom chain at N = 25 (204
  // unknowns): ~100 ms by QZ, ~4 ms by CVODE. The rule is deterministic (not
  // timed), so a trace is reproducible. kHill, kMonodromy and
  // kHarmonicMonodromy use only that one. Hill's method does not apply to
  // pinned auxiliaries (the pendulum's sin/cos) nor to quasi-periodic
  // solutions; the monodromy needs the original equations. A point whose
  // multipliers no method gives stays kUnknown; the summary says why.
  bool stability = true;
  StabilityMethod stability_method = StabilityMethod::kAuto;
  int max_hill_unknowns = 40;
  // kAuto, at the first point where two methods apply (Hill's problem of at
  // most max_cross_check_unknowns unknowns counting as applicable): every
  // applicable one is computed and their largest multiplier differences reported
  // (ContinuationSummary::stability_cross_check).
  int max_cross_check_unknowns = 200;
  HillOptions hill;
  HarmonicMonodromyOptions harmonic_monodromy;
  // Within this of the unit circle the largest non-trivial |mu| is neither
  // growth nor decay that a truncated (Hill) or tolerance-limited (CVODE)
  // computation can decide: kNeutral.
  double neutral_band = 1e-6;
  // Detect and locate branch points, period doublings and Neimark-Sacker
  // points (needs stability); locate each along the arc until the critical
  // multiplier's distance from the crossing (mu -/+ 1, |mu| - 1) is within
  // bifurcation_tolerance, or the bracket stops shrinking.
  bool detect_bifurcations = true;
  double bifurcation_tolerance = 1e-8;

  std::string IsValid() const;       // empty when valid
};

enum class ContinuationStatus {
  kCompleted,     // reached `end`
  kLeftRange,     // the branch turned back and left through `start`
  kStepTooSmall,  // the corrector failed down to the minimum step
  kPointLimit,    // max_points reached
  kTimeLimit,     // max_seconds reached
  kStartFailed,   // no solution at `start`
  kStopped,       // ContinuationProblem::stop_when said so (message: why)
};
const char* ToString(ContinuationStatus status);

enum class PointStability {
  kUnknown,   // not computed: no method applied (the summary says why)
  kStable,    // every non-trivial |mu| < 1 - neutral_band
  kUnstable,  // one |mu| > 1 + neutral_band
  kNeutral,   // the largest within the band: a bifurcation, or a conservative system
};
const char* ToString(PointStability stability);

struct ContinuationPoint {
  ContinuationPoint(double parameter_value, HarmonicSolution solution_here)
      : parameter(parameter_value), solution(std::move(solution_here)) {}
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
  StabilityMethod stability_method = StabilityMethod::kNone;  // the method that gave the multipliers
  // Floquet multipliers by decreasing modulus (Hill: one per differential
  // state), the trivial one's index (autonomous orbits) or -1, and the
  // largest non-trivial modulus as the verdict judged it (JudgedModulus:
  // a double 1 split by the orbit's error counts by its geometric mean).
  Multipliers multipliers;
  int trivial_multiplier = -1;
  double max_multiplier = 0;
  double neutral_band = 0;      // what max_multiplier was judged against (NeutralBand)
  double max_real_part = 0;     // log(max_multiplier) / T: the largest non-trivial Floquet exponent
  int bifurcation = -1;         // index into ContinuationSummary::bifurcations when one was located here
};

struct ContinuationSummary {
  ContinuationStatus status = ContinuationStatus::kStartFailed;
  ContinuationMethod method = ContinuationMethod::kPseudoArclength;
  std::string parameter;
  double start = 0, end = 0;   // the range asked for
  std::string message;
  std::string stability_note;  // why stability is unknown, if it is
  std::vector<ContinuationPoint> points;
  // Located folds, branch points, period doublings and Neimark-Sacker
  // points, in the order met along the branch.
  std::vector<BifurcationPoint> bifurcations;
  int hill_points = 0, monodromy_points = 0;  // stability computed by each
  int harmonic_monodromy_points = 0;
  // kAuto's comparison of both methods at the first point, e.g. "Hill
  // 2.7 ms, monodromy 0.5 ms at the first point; multipliers agree to 5e-10".
  std::string stability_cross_check;
  double stability_seconds = 0;               // spent on multipliers (and bifurcation location)
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

// Pseudo-arclength continuation from a known point, leaving it along
// `direction` (branch switching, rmhb/branch_switching.h): `start` solves the
// problem at `parameter` (on its own basis, which the trace keeps, with the
// rule's samples), and the first predictor is start + step direction/|direction|
// at the same parameter. The branch is followed until it leaves
// [problem.start, problem.end] (completed at `end`, left_range at `start`).
ContinuationSummary TraceBranchFrom(const ContinuationProblem& problem, double parameter,
                                    const HarmonicSolution& start, const HarmonicSolution& direction,
                                    const ContinuationOptions& options);

}  // namespace rmhb

#endif  // RMHB_CONTINUATION_H_

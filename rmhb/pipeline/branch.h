#ifndef RMHB_PIPELINE_BRANCH_H_
#define RMHB_PIPELINE_BRANCH_H_

// A branch of steady states of a model as one of its parameters moves, with
// what a user reads off each point:
//   ContinueOptions options;  options.parameter = "w";  options.from = 0.5;  options.to = 3;
//   options.harmonic_balance = prepared.options;
//   BranchSummary b = ContinueModel(model, prepared.guess, options);
// The branch is traced by rmhb::TraceBranch (rmhb/continuation.h:
// pseudo-arclength past folds, or natural-parameter steps), from the first
// point of the automatic start (SolveFromAnyStart: the guess, else a
// simulated start), the model rebuilt at every parameter value
// (WithParameters). Every point gets its peak max|x(t)| of the first
// variable, its Floquet multipliers and stability (Hill's method where it is
// small, else the monodromy of the original equations: rmhb/pipeline/
// monodromy.h), the branch its located folds, branch points, period
// doublings and Neimark-Sacker points; with switch_branches the period-2T
// branch from every period doubling and the torus past every Neimark-Sacker
// point (rmhb/branch_switching.h), validated against CVODE. Points get their errors
// against the model's exact reference, its definition check (a recast's
// auxiliaries against their definitions: physical or not), and on request
// its validation error against the original equations (ValidateOriginal:
// CVODE, or IDA for a DAE). `rmhb solve --continue` prints this summary;
// its JSON is ToJson().
// A branch that cannot be followed, or with non-physical points, is a
// status; misuse (invalid options, a parameter value the model refuses at
// either end of the range) throws std::invalid_argument.

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "integrators/trajectory_validation.h"
#include "rmhb/branch_switching.h"
#include "rmhb/continuation.h"
#include "rmhb/definition_check.h"
#include "rmhb/pipeline/model.h"
#include "rmhb/pipeline/torus.h"

namespace rmhb {

struct ContinueOptions {
  std::string parameter;  // any parameter of the model
  double from = 0, to = 1;
  HarmonicBalanceOptions harmonic_balance;  // of the first solve (PrepareSolve builds them)
  int steps = 20;         // first step |to - from| / steps; the step then adapts
  double max_step = 0;    // 0: |to - from| / 10, or the first step if larger
  bool natural = false;   // natural-parameter steps (stop at a fold) instead of pseudo-arclength
  bool stability = true;  // Floquet multipliers per point (ContinuationOptions::stability)
  StabilityMethod stability_method = StabilityMethod::kAuto;  // ContinuationOptions::stability_method
  bool validate = false;  // every point against the original equations
  int validate_periods = 1;  // of the slowest base
  // From every period doubling the period-2T branch, at every
  // Neimark-Sacker point the torus (validated over torus_periods periods of
  // the forcing against validate_tolerance, relative to max|state|).
  bool switch_branches = false;
  TorusOptions torus;
  double torus_periods = 20;
  double validate_tolerance = 1e-8;
  // Quasi-periodic models (METHOD.md s.18): every point's outermost
  // coefficients (OutermostCoefficients) are checked, and the trace of the
  // torus stops where they exceed tail_tolerance: the basis given no longer
  // resolves it. Its stability: Lyapunov exponents (TorusStability).
  double tail_tolerance = 1e-6;
  // On the adaptive index set (a target, no fixed shape), a torus stopped
  // there is solved again at that point with the set enriched from its
  // solution (METHOD.md s.8) and traced on, at most this many times.
  int max_enrichments = 4;
  // A periodic branch with an accuracy target (harmonic_balance.tolerance):
  // where a point's coefficient-tail estimate (EstimateTruncation, without
  // calibration) exceeds a quarter of the target (scaled by the last order
  // selection's calibration) and twice that of the order's own first point,
  // the order is selected again there for the target, warm from that
  // point, and the trace goes on at the higher order (at most
  // max_order_raises times); a selection short of the target stops the trace.
  int max_order_raises = 6;
  TorusStabilityOptions torus_stability;
  // A forced torus that stops near w2/w1 = p/q (q <= max_denominator) is
  // taken across the locking tongue: the periodic orbit of base w1/q is
  // solved inside it and followed to both edges (its folds), and the torus
  // is solved again past the far edge and traced on (at most max_tongues).
  bool locking = true;
  int max_denominator = 10;
  int max_tongues = 8;
  std::string IsValid() const;  // empty when valid
};

struct BranchPointReport {
  double peak = 0;                 // max|x(t)| of the first variable (PeakValue)
  std::string stability;           // stable, unstable, neutral or unknown
  double validation_error = NAN;   // when validated (NaN: the integration failed)
  // Against the model's exact reference at this parameter value, if any.
  double frequency_error = NAN, amplitude_error = NAN;
  std::optional<DefinitionCheck> definitions;  // when the model has auxiliaries
  // Tori: the outermost coefficients (adequacy of the basis), w2/w1, the
  // Lyapunov exponents (with stability), and which stretch of torus branch
  // (0, then 1 past the first locking tongue, ...) the point is on.
  double outermost = NAN;
  double ratio = NAN;
  std::optional<TorusStabilityReport> lyapunov;
  int segment = 0;
  // The larger of the two errors that exist.
  double reference_error() const;
  bool physical() const { return !definitions || definitions->physical; }
};

enum class BranchStatus {
  kCompleted,     // traced to the end of the range (or it left through its start)
  kStopped,       // the trace stopped (continuation.status and message say why)
  kNonPhysical,   // traced, but some points are non-physical (non_physical lists them)
  kSwitchFailed,  // traced, but a branch switch asked for failed (doubled/tori say which)
};
const char* ToString(BranchStatus status);  // "completed", "stopped", "non_physical", "switch_failed"

// The period-2T branch from a period doubling, with its points' reports
// (peak, stability, validation; no reference or definition check: those are
// the period-T model's).
struct DoubledBranchReport {
  BifurcationPoint from;
  DoubledBranch branch;  // not started when the message says it is another's end
  std::vector<BranchPointReport> reports;
};

// The torus past a Neimark-Sacker point and its trajectory check.
struct TorusReport {
  TorusStart start;
  std::optional<integrators::ValidationReport> validation;
  std::optional<ValidationVerdict> verdict;
  double periods = 0;  // of the forcing, validated over
};

// A locking tongue met along a forced torus' branch: where the torus
// stopped, the locked periodic branch (base w1/q) followed from inside the
// tongue toward each edge, the edges (its folds), and where the torus
// resumed past the far one.
struct TongueReport {
  Resonance lock;                   // w2 / w1 = lock.p / lock.q
  bool crossed = false;             // both edges found and the torus resumed past them
  std::string message;
  double torus_end = NAN;           // the last torus point before the tongue
  double ratio_end = NAN;           // its w2/w1
  double centre_estimate = NAN;     // where the locked orbit was first solved
  std::string locked_start;         // how (SolveFromAnyStart's route)
  double near_edge = NAN, far_edge = NAN;  // the folds, in the order the branch meets them
  double resumed_at = NAN;          // the first torus point past the tongue
  std::vector<ContinuationSummary> locked;  // toward the near edge, toward the far edge
  std::string Describe(const std::string& parameter) const;
};

struct BranchSummary {
  BranchStatus status = BranchStatus::kStopped;
  std::string message;
  ContinuationSummary continuation;        // the points themselves
  std::vector<BranchPointReport> reports;  // one per point
  std::vector<size_t> non_physical;        // indices of non-physical points
  bool has_reference = false;  // the model has an exact frequency or amplitude
  bool validated = false;
  int bases = 1;
  std::string start_route;  // of the first point (SolveFromAnyStart)
  bool switched = false;    // switch_branches was asked for
  std::vector<DoubledBranchReport> doubled;
  std::vector<TorusReport> tori;
  std::vector<TongueReport> tongues;  // a forced torus' locking tongues
  // Where a torus' index set was enriched: the parameter and the set's size
  // (harmonics) before and after.
  struct Enrichment {
    double parameter;
    int before, after;
  };
  std::vector<Enrichment> enrichments;
  // A periodic branch's orders raised for its target: before/after are orders.
  std::vector<Enrichment> order_raises;
  bool switch_failed() const;

  std::string BriefReport() const;  // the continuation's line
  // The brief line, the message, why stability is unknown, how the
  // stability methods compared, the located bifurcations, and (with `table`)
  // one row per point: parameter, frequencies, amplitude, residual,
  // stability, its method and max|mu|, [validation], [exact error], fold,
  // BP/PD/NS and NON-PHYSICAL marks; then the switched branches.
  std::string FullReport(bool table = true) const;
  // `rmhb solve --continue --json` without the command line's fields
  // (model, csv, plot).
  nlohmann::json ToJson() const;
};

// `model` at any parameter value (it is rebuilt at options.from); `guess`
// starts the first solve at options.from.
BranchSummary ContinueModel(const Model& model, const HarmonicSolution& guess, const ContinueOptions& options);

// max |x(t)| of the first variable: over one period, or for a quasi-periodic
// solution over 200 periods of the slowest base (a lower bound of the sup).
double PeakValue(const HarmonicSolution& solution, int variable = 0);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_BRANCH_H_

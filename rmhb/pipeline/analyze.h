#ifndef RMHB_PIPELINE_ANALYZE_H_
#define RMHB_PIPELINE_ANALYZE_H_

// The whole pipeline on a model, each stage timed and checked:
//   trajectory (CVODE or IDA on the original equations) -> identify (base
//   frequencies, labelled lines; frequency_id/) -> seed (the guess on the
//   basis; rmhb/seeding/) -> solve (RHB for one base, RMHB for several) ->
//   validate (the solution against a trajectory of the original equations).
//   AnalyzeSummary s = Analyze(model, options);
// With options.identify false the first three are skipped and the model's
// own guess (GuessAtOrder) starts the solve. A stage that fails is a status in the summary
// (with the residual reached for the solve), never an exception; misuse
// (invalid options, a model without original equations) throws
// std::invalid_argument.

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "frequency_id/frequency_identification.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/model.h"
#include "rmhb/seeding/identified_guess.h"

namespace rmhb {

struct AnalyzeOptions {
  HarmonicBalanceOptions solve;  // order, sampling rule, solver
  bool identify = true;
  double t_end = 0;            // of the record; 0: from the model's frequencies
  // Integrated, not recorded. -1: for a forced periodic model (every
  // frequency known) until the stroboscopic state settles (SettledState,
  // rmhb/pipeline/start.h, within its budget); otherwise a tenth of t_end.
  double transient = -1;
  int samples_per_period = 0;  // of the fastest base; 0: from the order
  int window = 0;              // Hann^q for identification; 0: automatic
  int validate_periods = 20;   // of the slowest base
  double validate_tolerance = 1e-8;  // relative to max|state| (JudgeValidation)
  // A forced torus (rmhb/pipeline/torus.h: two bases, the forcing known):
  // is its motion locked? Its stroboscopic state after locking_transient
  // forcing periods repeating every q <= max_locking_denominator periods
  // within locking_tolerance (LockedPeriods) says so, and the locked orbit
  // of base w1/q is analyzed instead of the torus (METHOD.md s.18). An
  // autonomous torus (both frequencies unknown) is locked when the model on
  // one unknown base, recorded after locking_transient periods of its
  // slowest guess (unless `transient` is given), converges and validates.
  bool detect_locking = true;
  int locking_transient = 1000;
  int max_locking_denominator = 10;
  double locking_tolerance = 1e-7;
  std::string IsValid() const;  // empty when valid
};

enum class AnalyzeStatus {
  kConverged,             // solved, physical, validated (see validation->max_error)
  kIdentificationFailed,  // no usable bases in the record
  kSeedFailed,            // the identified lines do not fit the model's bases
  kNotConverged,          // the solver stopped (solve->solver says why)
  kNonPhysical,           // converged to a non-physical solution (solve->non_physical)
  kValidationExceeded,    // solved, but the validation error is above the tolerance
};
// "converged", "identification_failed", "seed_failed", "not_converged", "non_physical",
// "validation_exceeded"
const char* ToString(AnalyzeStatus status);

struct RecordStage {
  seeding::RecordOptions record;
  std::string integrator;  // OriginalIntegrator: "CVODE Adams", "CVODE BDF", "IDA BDF"
  int settle_periods = 0;  // periods integrated until the motion settled (0: a fixed transient)
  // An autonomous model whose start (its initial_state, else the guess's
  // state, else rest) is an equilibrium is recorded from that state plus
  // this in every state component: the motion from an equilibrium never
  // leaves it, and a self-excited orbit is reached from next to it. 0: the
  // start as given.
  double rest_perturbation = 0;
  // How a periodic motion's record was sampled (RecordUnaliased): the asked
  // rate, or denser when a line would fold back; not measured (top_band 0)
  // for a torus or a given --samples-per-period.
  RecordSampling sampling;
  int samples = 0;
  double seconds = 0;
};

struct AnalyzeSummary {
  AnalyzeStatus status = AnalyzeStatus::kNotConverged;
  std::string message;
  bool identified = false;  // the first three stages ran
  std::optional<RecordStage> trajectory;
  std::optional<frequency_id::IdentificationSummary> identification;
  double identify_seconds = 0;
  std::optional<seeding::IdentifiedGuess> seed;
  double seed_seconds = 0;
  HarmonicBalanceProblem problem;  // as solved: the identified frequencies as guesses
  HarmonicBalanceOptions solve_options;  // as solved
  int validate_periods = 0;
  std::optional<HarmonicBalanceSummary> solve;
  std::optional<integrators::ValidationReport> validation;
  std::optional<ValidationVerdict> verdict;
  double validation_t_end = 0;
  // A forced torus' motion: "locked p:q ..." (the solution is then the
  // periodic orbit of base w1/q) or "quasi-periodic ..." with the number
  // judged; empty for other models.
  std::string motion;
  // A model without conditions of its own: those it got, and why (Model::conditions_note).
  std::vector<std::string> default_conditions;
  std::string conditions_note;
  double seconds = 0;

  bool ok() const { return status == AnalyzeStatus::kConverged; }
  // Solved (converged and physical), validated or not within the tolerance.
  bool solved() const { return ok() || status == AnalyzeStatus::kValidationExceeded; }
  // The status as `rmhb analyze` reports it: the solver's own status
  // ("no_convergence", ...) when the solve did not converge.
  std::string status_word() const;
  std::string BriefReport() const;
  // One line per stage: trajectory, identify (bases), seed, solve,
  // physical, the frequencies identified against solved, validate.
  std::string StageReport() const;
  std::string FullReport() const;  // StageReport() and BriefReport()
  // `rmhb analyze --json` without the command line's fields (model, the
  // total seconds with the model's loading, plot): status, message,
  // identified, stages {trajectory, identify, seed, solve, validate} and the
  // solution (SolutionJson) when solved.
  nlohmann::json ToJson() const;
};

AnalyzeSummary Analyze(const Model& model, const AnalyzeOptions& options);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_ANALYZE_H_

#ifndef RMHB_PIPELINE_SOLVE_H_
#define RMHB_PIPELINE_SOLVE_H_

// One steady state of a model, with everything a user asks of it:
//   SolveOptions options;  options.harmonic_balance = prepared.options;
//   options.validate = true;  options.stability = true;
//   SolveSummary s = SolveModel(model, prepared.guess, options);
//   std::printf("%s", s.FullReport().c_str());   // or s.ToJson().dump(1)
// The solve starts from the guess, and unless told otherwise from a
// simulated or identified start when the guess does not reach a physical
// solution (SolveFromAnyStart, rmhb/pipeline/start.h). A converged solution
// is measured against the model's exact reference (ErrorsAgainst), and on
// request validated against an integration of the original equations
// (ValidateOriginal, JudgeValidation: relative error against a tolerance)
// and its stability decided two ways (Stability). `rmhb solve` prints this
// summary; its JSON is ToJson().
// A solve that does not converge, converges to a non-physical solution or
// misses its validation tolerance is a status; misuse (invalid options,
// validating a model without original equations) throws
// std::invalid_argument.

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "integrators/trajectory_validation.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/model.h"
#include "rmhb/pipeline/reference.h"
#include "rmhb/pipeline/stability.h"
#include "rmhb/pipeline/start.h"

namespace rmhb {

struct SolveOptions {
  HarmonicBalanceOptions harmonic_balance;  // order, sampling rule, solver (PrepareSolve builds them)
  // true: the guess, then a simulated or identified start (SolveFromAnyStart);
  // false: the guess only.
  bool auto_start = true;
  StartOptions start;
  bool validate = false;            // against the original equations
  int validate_periods = 1;         // of the slowest base
  double validate_tolerance = 1e-8; // relative to max|state| (JudgeValidation)
  bool stability = false;           // Hill and the monodromy matrix, or a torus' Lyapunov exponents (Stability)
  std::string IsValid() const;      // empty when valid
};

enum class SolveStatus {
  kConverged,           // converged, physical (and within the validation tolerance when validated)
  kNotConverged,        // the solver stopped (harmonic_balance.solver says why and where)
  kNonPhysical,         // converged to a non-physical solution (harmonic_balance.non_physical)
  kValidationExceeded,  // converged, physical, validated with an error above the tolerance
};
// "converged", "not_converged", "non_physical", "validation_exceeded"
const char* ToString(SolveStatus status);

struct SolveValidation {
  integrators::ValidationReport report;
  ValidationVerdict verdict;
  int periods = 1;
  double t_end = 0;
  // "ok", "exceeds" (the error above the tolerance) or "failed" (the
  // integration did not finish).
  const char* status() const { return !report.ok ? "failed" : verdict.ok ? "ok" : "exceeds"; }
};

struct SolveSummary {
  SolveStatus status = SolveStatus::kNotConverged;
  std::string message;  // why, when not kConverged
  HarmonicBalanceSummary harmonic_balance;
  HarmonicBalanceOptions options;  // as solved
  std::string start_route;  // "guess", "simulation (...)", "identification" (StartedSolve::route)
  std::string start_note;   // why earlier routes were left
  // The model's exact answers and the solution's errors against them (a
  // converged solve of a model with a reference).
  ExactReference reference;
  std::optional<ReferenceErrors> errors;
  std::optional<SolveValidation> validation;
  std::optional<StabilitySummary> stability;
  // The process's peak resident memory at the end (solve, validation and
  // stability included), bytes; 0 where unknown.
  double peak_memory_bytes = 0;
  // The model, for the reports.
  std::string model_name, equation, recast;
  // Which equations were solved ("recast" or "original", Model::equations),
  // why, and the symmetries imposed because the guess had them
  // (ImposeGuessSymmetries).
  std::string equations = "recast", equations_note;
  // A model without conditions of its own: those it got, and why (Model::conditions_note).
  std::vector<std::string> default_conditions;
  std::string conditions_note;
  // An autonomous file without 'frequencies': where its guess came from (Model::frequency_note).
  std::string frequency_note;
  std::vector<std::string> symmetries;
  int bases = 1;

  bool converged() const { return harmonic_balance.converged(); }
  const HarmonicSolution& solution() const { return *harmonic_balance.solution; }
  // "converged", a solver status ("no_convergence", ...) or "non_physical".
  std::string status_word() const;
  std::string BriefReport() const;      // the harmonic balance summary's line
  // What `rmhb solve` prints: the brief line, the model and its recast,
  // status, residual, time, start, physical check, order selection,
  // condition, frequencies, coefficients, errors against the reference,
  // then RequestedReport().
  std::string FullReport() const;
  std::string RequestedReport() const;  // the stability and validation lines (asked for by name)
  // `rmhb solve --json` without the fields of the command line (model, eval, plot).
  nlohmann::json ToJson() const;
};

SolveSummary SolveModel(const Model& model, const HarmonicSolution& guess, const SolveOptions& options);
// From the model's own guess at the order (GuessAtOrder).
SolveSummary SolveModel(const Model& model, const SolveOptions& options);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_SOLVE_H_

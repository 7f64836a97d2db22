#ifndef RMHB_PIPELINE_CONVERGENCE_H_
#define RMHB_PIPELINE_CONVERGENCE_H_

// Error against run time, order by order, method by method: the paper's
// Tables 2 and 3 as one study.
//   ConvergenceSummary s = ConvergenceStudy(model, options);
// Each column is a method (RHB, HDHB, HB-AFT on the recast; for non-
// polynomial periodic models also RHB on the Taylor-expanded equations and
// HB-AFT on the original equations evaluated pointwise), a solver and a
// constraint scheme (METHOD.md s.5); each cell the solve at one order and
// its error against the strongest independent reference the model allows:
// its exact solution, amplitude or frequency (ExactReference), else a tight
// CVODE/IDA trajectory of the original equations started on the solution.
// A cell that fails is a status in the cell; misuse throws
// std::invalid_argument.

#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/model.h"

namespace rmhb {

// The paper's constraint schemes for a conservative system (METHOD.md s.5),
// on a recast problem whose first conditions are the user's (amplitude, then
// phase) and the rest pin auxiliaries:
//   kModel:   the model's own conditions;
//   kScheme1: every constant term balanced, the amplitude condition only;
//   kScheme2: the auxiliaries pinned, the amplitude condition;
//   kScheme3: the auxiliaries pinned, the phase condition.
enum class ConstraintScheme { kModel, kScheme1, kScheme2, kScheme3 };
const char* ToString(ConstraintScheme scheme);                   // "model", "scheme1", ...
ConstraintScheme ParseConstraintScheme(const std::string& name);  // throws std::invalid_argument
// The model's problem with the scheme's conditions. Throws when the model
// has too few conditions of its own.
HarmonicBalanceProblem WithConstraintScheme(const Model& model, ConstraintScheme scheme);

enum class StudyMethod { kRhb, kHdhb, kAft, kTaylor, kOriginal };
const char* ToString(StudyMethod method);               // "rhb", "hdhb", "aft", "taylor", "original"
StudyMethod ParseStudyMethod(const std::string& name);  // throws std::invalid_argument

struct ConvergenceOptions {
  std::vector<int> orders;
  // Empty: rhb, hdhb, aft, and for a periodic model with recast auxiliaries
  // also taylor and original.
  std::vector<StudyMethod> methods;
  std::vector<SolverMethod> solvers = {SolverMethod::kAuto};
  std::vector<ConstraintScheme> schemes = {ConstraintScheme::kModel};
  HarmonicBalanceOptions solve;  // everything but the order, rule and solver
  int taylor_order = 15;         // of the Taylor polynomials (taylor)
  int original_samples = 0;      // original: 0 = the recast's HB-AFT count
  int repeat = 1;                // keep the fastest of this many solves per cell
  std::string IsValid() const;
};

struct ConvergenceCell {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::string status = "skipped";  // converged, a solver status, refused, skipped
  std::string message;
  int samples = 0;
  int iterations = 0;
  double residual = kNaN, seconds = kNaN;
  double reciprocal_condition = kNaN;  // of the final Jacobian
  double frequency_error = kNaN, amplitude_error = kNaN, max_error = kNaN, trajectory_error = kNaN;
  double error = kNaN;   // the study's measure (ConvergenceSummary::error_measure)
  bool physical = true;  // of a converged cell
  std::string non_physical;
  double definition_error = kNaN;
  bool converged() const { return status == "converged"; }
};

struct ConvergenceColumn {
  std::string name;  // method[/solver][/scheme]
  StudyMethod method = StudyMethod::kRhb;
  SolverMethod solver = SolverMethod::kAuto;
  ConstraintScheme scheme = ConstraintScheme::kModel;
  std::string unavailable;  // why the column has no numbers
  std::vector<ConvergenceCell> cells;  // one per order
};

struct ConvergenceSummary {
  std::vector<int> orders;
  std::vector<ConvergenceColumn> columns;
  std::string error_measure;  // what `error` is
  int taylor_degree = -1;     // phi of the Taylor system, when a taylor column ran
  int converged = 0, physical = 0;  // cells
  // The model and the options, for the reports.
  std::string model_name, equation, reference_source;
  int degree = 0, bases = 1, taylor_order = 0, original_samples = 0;
  bool original_listed = false;  // an original column was asked for
  std::string BriefReport() const;
  // The table of `rmhb convergence`: one row per order, per column the
  // error, run time [ms] and samples ('!' after the error: non-physical),
  // then the notes (columns not run, non-physical and refused cells, the
  // Taylor and original variants).
  std::string FullReport() const;
  // `rmhb convergence --json` without the command line's fields (model,
  // plot): equation, error_measure, reference, orders, degree, columns (name,
  // method, solver, conditions, unavailable, rows of cells), taylor.
  nlohmann::json ToJson() const;
};

ConvergenceSummary ConvergenceStudy(const Model& model, const ConvergenceOptions& options);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_CONVERGENCE_H_

#ifndef RMHB_PIPELINE_CENSUS_H_
#define RMHB_PIPELINE_CENSUS_H_

// The paper's Table 1 experiment on a model: random starts solved by each
// sampling rule (RHB, HDHB, AFT), the distinct solutions each finds,
// classified physical-stable, physical-unstable or non-physical
// (rmhb/monte_carlo.h), and for a model with original equations each
// physical solution's stability checked by the Floquet multipliers of its
// CVODE monodromy matrix too (integrators/floquet.h):
//   CensusOptions options;  options.monte_carlo.solve = prepared.options;
//   CensusSummary s = Census(model, options);
// The starts run on threads; a program spreading them over processes passes
// its own runner (`rmhb montecarlo` under mpirun: rmhb/sweep/monte_carlo_mpi.h).
// `rmhb montecarlo` prints this summary; its JSON is ToJson(). A rule that
// converges from no start is a status; misuse throws std::invalid_argument.

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "rmhb/monte_carlo.h"
#include "rmhb/pipeline/model.h"

namespace rmhb {

struct CensusOptions {
  MonteCarloOptions monte_carlo;  // starts, range, seed, rules, solve options, ...
  // Each physical solution's Floquet multipliers from the original
  // equations (a second opinion on Hill's verdict), when the model has them.
  bool floquet = true;
  std::string IsValid() const { return monte_carlo.IsValid(); }
};

enum class CensusStatus {
  kCompleted,      // every rule converged from some start
  kNoneConverged,  // some rule converged from none of the starts
};
const char* ToString(CensusStatus status);  // "completed", "none_converged"

struct CensusSummary {
  CensusStatus status = CensusStatus::kCompleted;
  std::string message;
  MonteCarloSummary monte_carlo;
  MonteCarloOptions options;  // as run (range, seed, match tolerance)
  int ranks = 1;              // processes the starts ran on
  std::string BriefReport() const { return monte_carlo.BriefReport(); }
  // The starts, range, seed, reference, threads and time, then the table
  // (MonteCarloSummary::FullReport).
  std::string FullReport() const;
  // `rmhb montecarlo --json` without the model argument: starts, range,
  // seed, order, reference_order, match_tolerance, threads, ranks, seconds,
  // and per method its counts, shares and clusters (class, count, share,
  // amplitude, reference distance, stability, solution).
  nlohmann::json ToJson() const;
};

// How the starts are solved and counted: RunMonteCarlo by default.
using MonteCarloRunner = std::function<MonteCarloSummary(const HarmonicBalanceProblem&, const MonteCarloOptions&)>;

CensusSummary Census(const Model& model, const CensusOptions& options, const MonteCarloRunner& run = nullptr);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_CENSUS_H_

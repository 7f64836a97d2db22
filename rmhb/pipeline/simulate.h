#ifndef RMHB_PIPELINE_SIMULATE_H_
#define RMHB_PIPELINE_SIMULATE_H_

// The ORIGINAL equations of a model integrated from its initial state and
// sampled uniformly: the motion with its transient, which a harmonic balance
// solution leaves out, and the reference the validations use.
//   SimulateSummary s = Simulate(model, SimulateOptions{});
//   s.result.trajectory.times, s.result.trajectory.states
// CVODE (Adams, or BDF for a stiff model or on request), or IDA for a model
// with algebraic equations (it first makes the algebraic states consistent,
// IDACalcIC). `rmhb simulate` prints this summary; its JSON is ToJson().
// An integration that stops early is a status (with the rows reached);
// misuse (invalid options, a model without original equations) throws
// std::invalid_argument.

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "integrators/integration_result.h"
#include "rmhb/pipeline/model.h"

namespace rmhb {

struct SimulateOptions {
  std::optional<double> t_end;  // unset: 20 periods of the slowest base frequency
  std::optional<double> dt;     // unset: a 64th of the fastest period
  double relative_tolerance = 1e-12;
  double absolute_tolerance = 1e-14;
  enum class Method { kAuto, kAdams, kBdf } method = Method::kAuto;  // kAuto: the model's own (stiff: BDF)
  std::string IsValid() const;  // empty when valid
};

struct SimulateSummary {
  integrators::IntegrationResult result;
  double t_end = 0, dt = 0;
  double relative_tolerance = 0, absolute_tolerance = 0;
  std::vector<std::string> state_names;
  Eigen::VectorXd initial_state;
  bool ok() const { return result.ok(); }
  // "<integrator>, rtol r, atol a: R rows to t = T in S steps, X ms"
  std::string BriefReport() const;
  // `rmhb simulate --json` without the files (csv, plot): status, message,
  // integrator, rtol, atol, t_end, dt, rows, steps, rhs_evaluations,
  // seconds, states, initial_state, final_state.
  nlohmann::json ToJson() const;
};

SimulateSummary Simulate(const Model& model, const SimulateOptions& options);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_SIMULATE_H_

#include "rmhb/pipeline/simulate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "rmhb/pipeline/report.h"

namespace rmhb {

std::string SimulateOptions::IsValid() const {
  if (t_end && (!(*t_end > 0) || !std::isfinite(*t_end))) return "--t-end must be a finite number > 0";
  if (dt && (!(*dt > 0) || !std::isfinite(*dt))) return "--dt must be a finite number > 0";
  if (!(relative_tolerance > 0) || !(absolute_tolerance > 0) || !std::isfinite(relative_tolerance) ||
      !std::isfinite(absolute_tolerance))
    return "--rtol and --atol must be finite numbers > 0";
  return "";
}

SimulateSummary Simulate(const Model& model, const SimulateOptions& o) {
  if (!model.original && !model.original_dae)
    throw std::invalid_argument("cannot integrate the model: " + model.original_error);
  if (const std::string error = o.IsValid(); !error.empty()) throw std::invalid_argument(error);
  SimulateSummary s;
  const std::vector<double>& w = model.problem.frequencies;
  s.t_end = o.t_end ? *o.t_end : 20 * 2 * M_PI / *std::min_element(w.begin(), w.end());
  s.dt = o.dt ? *o.dt : 2 * M_PI / *std::max_element(w.begin(), w.end()) / 64;
  const double count = std::floor(s.t_end / s.dt + 1e-9) + 1;
  if (count > 5e7)
    throw std::invalid_argument("--t-end/--dt would write " + std::to_string(count) + " rows (at most 5e7)");
  std::vector<double> times(static_cast<size_t>(count));
  for (size_t i = 0; i < times.size(); ++i) times[i] = i * s.dt;
  integrators::IntegratorOptions io;
  const bool bdf = o.method == SimulateOptions::Method::kBdf || (o.method == SimulateOptions::Method::kAuto && model.stiff);
  io.method = bdf ? integrators::IntegratorOptions::Method::kBdf : integrators::IntegratorOptions::Method::kAdams;
  io.relative_tolerance = s.relative_tolerance = o.relative_tolerance;
  io.absolute_tolerance = s.absolute_tolerance = o.absolute_tolerance;
  s.result = SimulateOriginal(model, w, model.initial_state, times, io);
  s.state_names = model.state_names;
  s.initial_state = model.initial_state;
  return s;
}

std::string SimulateSummary::BriefReport() const {
  char text[512];
  std::snprintf(text, sizeof text, "%s, rtol %g, atol %g: %d rows to t = %g in %ld steps, %.1f ms", result.solver.c_str(),
                relative_tolerance, absolute_tolerance, result.trajectory.size(),
                result.trajectory.size() ? result.trajectory.times.back() : 0.0, result.steps, result.seconds * 1e3);
  return text;
}

nlohmann::json SimulateSummary::ToJson() const {
  const integrators::Trajectory& tr = result.trajectory;
  nlohmann::json initial = nlohmann::json::array(), last = nlohmann::json::array();
  for (int j = 0; j < initial_state.size(); ++j) initial.push_back(JsonNumber(initial_state(j)));
  if (tr.size() > 0)
    for (int j = 0; j < tr.dimension(); ++j) last.push_back(JsonNumber(tr.states(tr.size() - 1, j)));
  return {{"status", result.ok() ? "ok" : "failed"},
          {"message", result.message},
          {"integrator", result.solver},
          {"rtol", relative_tolerance},
          {"atol", absolute_tolerance},
          {"t_end", t_end},
          {"dt", dt},
          {"rows", tr.size()},
          {"steps", result.steps},
          {"rhs_evaluations", result.rhs_evaluations},
          {"seconds", result.seconds},
          {"states", state_names},
          {"initial_state", initial},
          {"final_state", last}};
}

}  // namespace rmhb

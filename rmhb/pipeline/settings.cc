#include "rmhb/pipeline/settings.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rmhb {

std::string SolveSettings::IsValid() const {
  if ((order_given || order != -1) && order < 1) return "--order must be >= 1 (got " + std::to_string(order) + ")";
  if (!(residual_tol > 0) || !std::isfinite(residual_tol))
    return "--residual-tol must be finite and > 0 (got " + std::to_string(residual_tol) + ")";
  if ((samples_given || samples != -1) && samples < 1)
    return "--samples must be >= 1 (got " + std::to_string(samples) + ")";
  if (!(tol >= 0) || !std::isfinite(tol)) return "--tol must be a finite number >= 0 (got " + std::to_string(tol) + ")";
  if (!(default_tol >= 0) || !std::isfinite(default_tol)) return "default_tol must be a finite number >= 0";
  if (!(default_torus_tol >= 0) || !std::isfinite(default_torus_tol))
    return "default_torus_tol must be a finite number >= 0";
  if (tol_quantity != "state" && tol_quantity != "frequency")
    return "--tol-quantity must be state or frequency (got '" + tol_quantity + "')";
  if (!(max_jacobian_gib > 0) || !std::isfinite(max_jacobian_gib)) return "--max-jacobian-gib must be finite and > 0";
  if (sampling != "torus" && sampling != "gcd") return "--sampling must be torus or gcd (got '" + sampling + "')";
  if (shape != "diamond" && shape != "box") return "--basis must be diamond or box (got '" + shape + "')";
  if (max_iterations < 1) return "--max-iterations must be >= 1";
  if (max_order < 1) return "--max-order must be >= 1";
  if (equations != "recast" && equations != "original" && equations != "auto")
    return "--equations must be recast, original or auto (got '" + equations + "')";
  return "";
}

PreparedSolve PrepareSolve(Model model, const SolveSettings& a) {
  if (const std::string error = a.IsValid(); !error.empty()) throw std::invalid_argument(error);
  if (!a.frequencies.empty()) SetFrequencies(a.frequencies, &model);
  HarmonicBalanceProblem& problem = model.problem;
  const int bases = static_cast<int>(problem.frequencies.size());
  // Each unknown frequency needs a condition (its phase); ModelFromDefinition
  // supplies them only for an ODE model with one unknown base.
  if (model.from_file && model.num_user_conditions < problem.num_unknown_frequencies())
    throw std::invalid_argument(
        model.name + ": unknown base frequencies " + std::to_string(problem.num_unknown_frequencies()) +
        ", conditions at t = 0 " + std::to_string(model.num_user_conditions) +
        ": each unknown frequency needs one (a phase condition such as \"x'(0) = 0\"), a conservative orbit also "
        "its amplitude (such as \"x(0) = 1.5\"); they are supplied by default only for ODE models with one unknown "
        "base and no conditions");

  HarmonicBalanceOptions options;
  options.order = a.order > 0 ? a.order : model.default_order;
  options.rule = ParseSamplingRule(a.method);
  if (a.samples > 0) options.samples.assign(bases, a.samples);
  options.allow_aliasing = a.allow_aliasing;
  const double default_tol = a.default_tol > 0 ? a.default_tol : bases > 1 ? a.default_torus_tol : 0;
  options.tolerance = a.tol > 0 ? a.tol
                      : !a.order_given && !a.samples_given && options.rule == SamplingRule::kRhb ? default_tol
                                                                                                 : 0;
  options.tolerance_quantity = ParseTargetQuantity(a.tol_quantity);
  // The default target is a wish, not an order: bounded at 4x the start (at
  // least 64), and not reaching it is reported, not a failure (a non-smooth
  // model's algebraic decay would otherwise climb to --max-order).
  const bool default_target = !(a.tol > 0) && options.tolerance > 0;
  options.soft_tolerance = default_target;
  options.max_order = std::max(default_target ? std::min(a.max_order, std::max(4 * options.order, 64)) : a.max_order,
                               options.order);
  options.solver.method = ParseSolverMethod(a.solver);
  options.solver.max_iterations = a.max_iterations;
  options.solver.scaling = ParseScaling(a.scaling);
  options.solver.linear_solver = ParseLinearSolver(a.linear_solver);
  options.solver.residual_tolerance = a.residual_tol;
  options.shape = a.shape == "box" ? BasisShape::kBox : BasisShape::kDiamond;
  options.quasi_periodic_sampling =
      a.sampling == "gcd" ? QuasiPeriodicSampling::kGcd : QuasiPeriodicSampling::kTorus;
  // Without an explicit shape and with a target, several bases get the
  // adaptive index set (METHOD.md s.8).
  if (!a.shape_given && bases > 1 && options.tolerance > 0) options.shape = BasisShape::kAdaptive;
  options.max_jacobian_bytes = a.max_jacobian_gib * double(1L << 30);
  CheckJacobianSize(problem, options);  // before a guess at that order is built
  HarmonicSolution guess = GuessAtOrder(model, options.order);
  return PreparedSolve{std::move(model), std::move(options), std::move(guess)};
}

std::vector<double> ParseNumberList(const std::string& text, const char* what) {
  std::vector<double> out;
  size_t pos = 0;
  while (pos <= text.size()) {
    const size_t next = text.find_first_of(",:", pos);
    const std::string item = text.substr(pos, next == std::string::npos ? std::string::npos : next - pos);
    size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (item.empty() || used != item.size() || !std::isfinite(v))
      throw std::invalid_argument(std::string(what) + ": '" + item + "' is not a finite number");
    out.push_back(v);
    if (next == std::string::npos) break;
    pos = next + 1;
  }
  return out;
}

std::pair<std::string, double> ParseAssignment(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument("--set expects name=value, got '" + text + "'");
  const std::string name = text.substr(0, eq), value = text.substr(eq + 1);
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != value.size())
    throw std::invalid_argument("--set " + name + ": '" + value + "' is not a number");
  if (!std::isfinite(v)) throw std::invalid_argument("--set " + name + ": value must be finite");
  return {name, v};
}

std::map<std::string, double> ParseOverrides(const std::vector<std::string>& assignments) {
  std::map<std::string, double> values;
  for (const auto& s : assignments) {
    auto [name, v] = ParseAssignment(s);
    values[name] = v;
  }
  return values;
}

}  // namespace rmhb

#include "rmhb/cli/solve_setup.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "rmhb/cli/commands.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;

json Coefficients(const HarmonicSolution& s, int j) {
  const auto& c = s.coefficients();
  json cos = json::array(), sin = json::array();
  cos.push_back(Number(c(j, 0)));
  sin.push_back(0.0);
  for (int k = 1; k < s.basis().size(); ++k) {
    cos.push_back(Number(c(j, 2 * k - 1)));
    sin.push_back(Number(c(j, 2 * k)));
  }
  return {{"cos", cos}, {"sin", sin}};
}

// --frequencies "w1,?w2": values of known bases, guesses of unknown ones.
void ApplyFrequencies(const std::string& text, HarmonicBalanceProblem* problem) {
  const int bases = static_cast<int>(problem->frequencies.size());
  std::vector<std::string> items;
  std::string item;
  for (char c : text + ",") {
    if (c == ',') items.push_back(item), item.clear();
    else item += c;
  }
  if (static_cast<int>(items.size()) != bases)
    throw std::invalid_argument("--frequencies: the model has " + std::to_string(bases) +
                                " base frequencies, got " + std::to_string(items.size()));
  if (problem->unknown_frequency.empty()) problem->unknown_frequency.assign(bases, false);
  for (int b = 0; b < bases; ++b) {
    const bool unknown = !items[b].empty() && items[b][0] == '?';
    const double w = ParseNumberList(unknown ? items[b].substr(1) : items[b], "--frequencies")[0];
    if (!(w > 0)) throw std::invalid_argument("--frequencies: frequencies must be > 0");
    problem->frequencies[b] = w;
    if (unknown) problem->unknown_frequency[b] = true;
  }
}

// "1e9" as 1000000000 for integer options, so that a size written as a
// power of ten reaches the size checks (exit 2 naming the memory it needs)
// instead of a conversion error. Anything else is left to CLI11.
std::string WholeNumber(std::string text) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    return text;
  }
  if (used != text.size() || v != std::floor(v) || std::abs(v) > 2147483647.0) return text;
  return std::to_string(static_cast<long>(v));
}

}  // namespace

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

json Number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

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

void AddSolveSettings(CLI::App* app, SolveSettings* a) {
  app->add_option("model", a->model,
                  "Example name (see `rmhb list`) or model file (examples/models/*.yaml)")
      ->required();
  app->add_option("--set", a->set, "Override a parameter: --set name=value (repeatable)");
  app->add_option("--order,-N,--p", a->order,
                  "Harmonic order: N for one base frequency, p (|m|+|n| <= p) for several "
                  "(default: the model's)")
      ->transform(WholeNumber)
      ->each([a](const std::string&) { a->order_given = true; });
  app->add_option("--frequencies", a->frequencies,
                  "Base frequencies w1[,w2]: values of known ones, guesses of unknown ones; "
                  "prefix ? to make one unknown (e.g. 2.3,?0.95)");
  app->add_option("--sampling", a->sampling,
                  "Quasi-periodic sampling: torus (2-D grid, default) or gcd (Theorem 2)")
      ->check(CLI::IsMember({"torus", "gcd"}));
  app->add_option("--basis", a->shape,
                  "Quasi-periodic index set: diamond (|m|+|n| <= p) or box (default: the "
                  "model's own when it has one, else diamond)")
      ->check(CLI::IsMember({"diamond", "box"}))
      ->each([a](const std::string&) { a->shape_given = true; });
  app->add_option("--samples,-M", a->samples,
                  "Collocation samples M (default: by --method; below the alias-free bound "
                  "needs --allow-aliasing)")
      ->transform(WholeNumber)
      ->each([a](const std::string&) { a->samples_given = true; });
  app->add_option("--method", a->method,
                  "rhb (alias-free M, default), hdhb (M = 2N+1, aliases), aft (M = 2^k >= 2 phi N+1)")
      ->check(CLI::IsMember({"rhb", "hdhb", "aft"}));
  app->add_option("--solver", a->solver,
                  "newton, lm (Levenberg-Marquardt), tikhonov, or auto (Newton when square, "
                  "L-M otherwise)")
      ->check(CLI::IsMember({"auto", "newton", "lm", "tikhonov"}));
  app->add_option("--scaling", a->scaling,
                  "equilibrate (default: Ruiz row and column equilibration, unit-invariant convergence "
                  "tests, so a model in SI units converges like its nondimensional form) or none "
                  "(absolute tests on max|F| and the step)")
      ->check(CLI::IsMember({"equilibrate", "none"}));
  app->add_option("--max-iterations", a->max_iterations, "Nonlinear solver iteration limit (default 100)")
      ->check(CLI::Range(1, 100000));
  app->add_flag("--allow-aliasing", a->allow_aliasing, "Accept M below the alias-free bound");
  app->add_option("--residual-tol", a->residual_tol,
                  "Converged when max|F| <= this (default 1e-15; finite and > 0); with "
                  "--scaling equilibrate on the scaled residual, relative to the scaled unknowns");
  app->add_option("--tol", a->tol,
                  "Choose the order automatically: from --order (or the model's default), "
                  "raise it warm-started until two successive orders agree to TOL (relative "
                  "frequency, scaled coefficients); reports the orders tried and the estimate. "
                  "Not reached by --max-order: exit 3");
  app->add_option("--max-jacobian-gib", a->max_jacobian_gib,
                  "Refuse (exit 2) an order whose dense Jacobian needs more than this many GiB; "
                  "--tol stops at the largest order under it (default 4)");
  app->add_option("--max-order", a->max_order, "Highest order --tol may choose (default 5000)")
      ->check(CLI::Range(1, 20000));
}

ProblemSource LoadSolveProblem(const SolveSettings& a, const std::map<std::string, double>& overrides) {
  std::map<std::string, double> values = ParseOverrides(a.set);
  for (const auto& [name, value] : overrides) values[name] = value;
  ProblemSource source = LoadProblem(a.model, values);
  if (!a.frequencies.empty()) ApplyFrequencies(a.frequencies, &source.problem);
  return source;
}

PreparedSolve PrepareSolve(const SolveSettings& a, const std::map<std::string, double>& overrides) {
  if ((a.order_given || a.order != -1) && a.order < 1)
    throw std::invalid_argument("--order must be >= 1 (got " + std::to_string(a.order) + ")");
  if (!(a.residual_tol > 0) || !std::isfinite(a.residual_tol))
    throw std::invalid_argument("--residual-tol must be finite and > 0 (got " + std::to_string(a.residual_tol) + ")");
  if ((a.samples_given || a.samples != -1) && a.samples < 1)
    throw std::invalid_argument("--samples must be >= 1 (got " + std::to_string(a.samples) + ")");
  if (!(a.tol >= 0) || !std::isfinite(a.tol))
    throw std::invalid_argument("--tol must be a finite number >= 0 (got " + std::to_string(a.tol) + ")");
  if (!(a.max_jacobian_gib > 0) || !std::isfinite(a.max_jacobian_gib))
    throw std::invalid_argument("--max-jacobian-gib must be finite and > 0");
  ProblemSource source = LoadSolveProblem(a, overrides);
  HarmonicBalanceProblem& problem = source.problem;
  const int bases = static_cast<int>(problem.frequencies.size());

  HarmonicBalanceOptions options;
  options.order = a.order > 0 ? a.order : source.default_order;
  options.rule = ParseSamplingRule(a.method);
  if (a.samples > 0) options.samples.assign(bases, a.samples);
  options.allow_aliasing = a.allow_aliasing;
  options.tolerance = a.tol;
  options.max_order = std::max(a.max_order, options.order);
  options.solver.method = ParseSolverMethod(a.solver);
  options.solver.max_iterations = a.max_iterations;
  options.solver.scaling = ParseScaling(a.scaling);
  options.solver.residual_tolerance = a.residual_tol;
  options.shape = a.shape == "box" ? BasisShape::kBox : BasisShape::kDiamond;
  options.quasi_periodic_sampling =
      a.sampling == "gcd" ? QuasiPeriodicSampling::kGcd : QuasiPeriodicSampling::kTorus;
  // An explicit --basis overrides the example's own index set.
  if (source.basis_for_order && !a.shape_given) options.basis_for_order = source.basis_for_order;
  options.max_jacobian_bytes = a.max_jacobian_gib * double(1L << 30);
  CheckJacobianSize(problem, options);  // before a guess at that order is built
  HarmonicSolution guess = GuessAtOrder(source, options.order);
  return PreparedSolve{std::move(source), std::move(options), std::move(guess)};
}

json SolutionJson(const HarmonicSolution& sol) {
  const int bases = static_cast<int>(sol.frequencies().size());
  json out;
  json freqs = json::array();
  for (double w : sol.frequencies()) freqs.push_back(Number(w));
  out["frequencies"] = freqs;
  json coeffs = json::object(), aux = json::object();
  for (int j = 0; j < sol.num_variables(); ++j) {
    const auto& v = sol.variables()[j];
    (v.role == VariableRole::kAuxiliary ? aux : coeffs)[v.name] = Coefficients(sol, j);
  }
  out["coefficients"] = coeffs;
  json harmonics = json::array();
  for (const auto& k : sol.basis().harmonics()) harmonics.push_back(bases == 1 ? json(k[0]) : json(k));
  out["harmonics"] = harmonics;
  out["auxiliary_coefficients"] = aux;
  return out;
}

json PhysicalJson(const HarmonicBalanceSummary& summary) {
  json out = json::object();
  if (!summary.converged()) return out;
  out["physical"] = summary.physical;
  if (!summary.physical) out["non_physical"] = summary.non_physical;
  if (const auto& c = summary.definition_check) {
    out["definition_error"] = Number(c->error);
    out["definition_worst"] = c->worst_variable;
    out["definition_worst_time"] = Number(c->worst_time);
    out["definition_tolerance"] = Number(c->tolerance);
    out["definition_points"] = c->points;
    out["definition_seconds"] = c->seconds;
  }
  return out;
}

std::string PhysicalLine(const HarmonicBalanceSummary& summary) {
  if (!summary.converged()) return "";
  if (!summary.physical) return "NO: " + summary.non_physical;
  if (summary.definition_check) return "yes: " + summary.definition_check->Report();
  return "yes (no collapsed frequency; no auxiliaries to check)";
}

}  // namespace rmhb::cli

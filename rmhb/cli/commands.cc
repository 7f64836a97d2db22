#include "rmhb/cli/commands.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <sstream>

#include "examples/example_system.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/harmonic_balance.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;

// JSON cannot hold NaN/inf; a non-finite number must never be printed as a
// result, so it becomes null.
json Number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

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

void AddSolveOptions(CLI::App* app, SolveArgs* a) {
  app->add_option("model", a->model, "Example name (see `rmhb list`)")->required();
  app->add_option("--set", a->set, "Override a parameter: --set name=value (repeatable)");
  app->add_option("--order,-N", a->order, "Harmonic order N (default: the example's)");
  app->add_option("--samples,-M", a->samples,
                  "Collocation samples M (default: by --method; below the alias-free bound "
                  "needs --allow-aliasing)");
  app->add_option("--method", a->method,
                  "rhb (alias-free M, default), hdhb (M = 2N+1, aliases), aft (M = 2^k >= 2 phi N+1)")
      ->check(CLI::IsMember({"rhb", "hdhb", "aft"}));
  app->add_option("--solver", a->solver,
                  "newton, lm (Levenberg-Marquardt), tikhonov, or auto (Newton when square, "
                  "L-M otherwise)")
      ->check(CLI::IsMember({"auto", "newton", "lm", "tikhonov"}));
  app->add_option("--max-iterations", a->max_iterations, "Nonlinear solver iteration limit (default 100)")
      ->check(CLI::Range(1, 100000));
  app->add_flag("--allow-aliasing", a->allow_aliasing, "Accept M below the alias-free bound");
  app->add_flag("--validate", a->validate,
                "Integrate the original equations with SUNDIALS from the solution's initial "
                "state and report the maximum error");
  app->add_option("--validate-periods", a->validate_periods, "Periods to integrate (default 1)")
      ->check(CLI::Range(1, 100000));
  app->add_flag("--json", a->json, "Machine-readable output");
  app->add_flag("--quiet,-q", a->quiet, "Only the summary line");
}

int RunList(bool as_json) {
  json out = json::array();
  for (const auto& e : examples::AllExamples()) {
    json params = json::array();
    for (const auto& p : e.parameters)
      params.push_back({{"name", p.name}, {"default", p.value}, {"meaning", p.meaning}});
    out.push_back({{"name", e.name}, {"description", e.description}, {"equation", e.equation},
                   {"parameters", params}});
    if (!as_json) {
      std::printf("%-18s %s\n%-18s   %s\n", e.name.c_str(), e.description.c_str(), "",
                  e.equation.c_str());
      for (const auto& p : e.parameters)
        std::printf("%-18s   %-8s = %-8g %s\n", "", p.name.c_str(), p.value, p.meaning.c_str());
    }
  }
  if (as_json) std::cout << out.dump(1) << "\n";
  return kExitOk;
}

int RunSolve(const SolveArgs& a) {
  std::map<std::string, double> values;
  for (const auto& s : a.set) {
    auto [name, v] = ParseAssignment(s);
    values[name] = v;
  }
  if (a.order != -1 && a.order < 1)
    throw std::invalid_argument("--order must be >= 1 (got " + std::to_string(a.order) + ")");
  if (a.samples != -1 && a.samples < 1)
    throw std::invalid_argument("--samples must be >= 1 (got " + std::to_string(a.samples) + ")");
  examples::ExampleSetup setup = examples::BuildExample(a.model, values);

  HarmonicBalanceOptions options;
  options.order = a.order > 0 ? a.order : setup.default_order;
  options.rule = ParseSamplingRule(a.method);
  if (a.samples > 0) options.samples = {a.samples};
  options.allow_aliasing = a.allow_aliasing;
  options.solver.method = ParseSolverMethod(a.solver);
  options.solver.max_iterations = a.max_iterations;
  const HarmonicBalanceSummary summary = SolveHarmonicBalance(setup.problem, setup.guess, options);
  const HarmonicSolution& sol = *summary.solution;
  const bool converged = summary.converged();

  json out;
  out["model"] = a.model;
  out["status"] = converged ? "converged" : ToString(summary.solver.status);
  out["message"] = summary.solver.message;
  out["method"] = ToString(options.rule);
  out["solver"] = ToString(summary.solver.method);
  out["order"] = options.order;
  out["samples"] = summary.samples.size() == 1 ? json(summary.samples[0]) : json(summary.samples);
  out["alias_free_samples"] = summary.alias_free_samples[0];
  out["alias_free"] = summary.alias_free;
  out["degree"] = summary.degree;
  out["iterations"] = summary.solver.iterations;
  out["residual"] = Number(summary.solver.final_residual);
  out["seconds"] = summary.seconds;
  json freqs = json::array();
  for (double w : sol.frequencies()) freqs.push_back(Number(w));
  out["frequencies"] = freqs;
  if (converged) {
    json coeffs = json::object(), aux = json::object();
    for (int j = 0; j < sol.num_variables(); ++j) {
      const auto& v = sol.variables()[j];
      (v.role == VariableRole::kAuxiliary ? aux : coeffs)[v.name] = Coefficients(sol, j);
    }
    out["coefficients"] = coeffs;
    out["auxiliary_coefficients"] = aux;
  }
  json reference = json::object();
  if (converged && setup.reference.has_frequency())
    reference["frequency_error"] = Number(sol.frequencies()[0] - setup.reference.frequency);
  if (converged && setup.reference.has_amplitude())
    reference["amplitude_error"] =
        Number(sol.Amplitude(sol.IndexOf(setup.reference.amplitude_variable)) -
               setup.reference.amplitude);
  if (converged && setup.reference.solution) {
    const double T = 2 * M_PI / setup.reference.frequency;
    double worst = 0;
    for (int i = 0; i <= 2000; ++i) {
      const double t = T * i / 2000;
      worst = std::max(worst, std::abs(sol.Value(0, t) - setup.reference.solution(t)));
    }
    reference["max_error"] = Number(worst);
  }
  if (!reference.empty()) {
    reference["source"] = setup.reference.source;
    out["reference"] = reference;
  }
  json validation;
  if (a.validate && converged) {
    integrators::OdeSystem ode{setup.original.dimension(), setup.original.rhs};
    const integrators::ValidationReport v = integrators::ValidateTrajectory(
        ode, [&](double t) { return setup.original.state(sol, t); },
        a.validate_periods * 2 * M_PI / sol.frequencies()[0], setup.original.stiff);
    validation = {{"status", v.ok ? "ok" : "failed"}, {"max_error", Number(v.max_error)},
                  {"periods", a.validate_periods}, {"seconds", v.seconds},
                  {"integrator", v.integrator}, {"message", v.message}};
    out["validation"] = validation;
  }

  if (a.json) {
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("%s\n", summary.BriefReport().c_str());
    if (!a.quiet) {
      const auto* ex = examples::FindExample(a.model);
      std::printf("\n%s: %s\n", a.model.c_str(), ex->equation.c_str());
      std::printf("recast (phi = %d):\n%s", summary.degree, setup.problem.system.ToString().c_str());
      std::printf("status       %s%s%s\n", out["status"].get<std::string>().c_str(),
                  summary.solver.message.empty() ? "" : ": ", summary.solver.message.c_str());
      std::printf("residual     %.3e after %d iterations (%s)\n", summary.solver.final_residual,
                  summary.solver.iterations, ToString(summary.solver.method));
      std::printf("time         %.3f ms\n", summary.seconds * 1e3);
      if (converged) {
        for (double w : sol.frequencies())
          std::printf("frequency    %.17g  (period %.17g)\n", w, 2 * M_PI / w);
        for (int j = 0; j < sol.num_variables(); ++j) {
          if (sol.variables()[j].role == VariableRole::kAuxiliary) continue;
          std::printf("%-12s", sol.variables()[j].name.c_str());
          const int shown = std::min(sol.basis().size(), 6);
          for (int k = 0; k < shown; ++k)
            std::printf(" k=%d:(%.6g, %.6g)", k, k ? sol.coefficients()(j, 2 * k - 1) : sol.coefficients()(j, 0),
                        k ? sol.coefficients()(j, 2 * k) : 0.0);
          std::printf("%s\n", sol.basis().size() > shown ? " ..." : "");
        }
        if (reference.contains("frequency_error"))
          std::printf("error        frequency %.3e (against %s)\n",
                      reference["frequency_error"].get<double>(), setup.reference.source.c_str());
        if (reference.contains("amplitude_error"))
          std::printf("error        amplitude %.3e\n", reference["amplitude_error"].get<double>());
        if (reference.contains("max_error"))
          std::printf("error        max over one period %.3e\n", reference["max_error"].get<double>());
      }
      if (!validation.is_null())
        std::printf("validation   %s: max error %.3e over %d period(s) against %s (%.1f ms)\n",
                    validation["status"].get<std::string>().c_str(),
                    validation["max_error"].is_null() ? NAN : validation["max_error"].get<double>(),
                    a.validate_periods, validation["integrator"].get<std::string>().c_str(),
                    validation["seconds"].get<double>() * 1e3);
    }
  }
  if (!converged) {
    if (!a.json)
      std::fprintf(stderr, "rmhb: not converged: %s (max|F| = %.3e)\n",
                   summary.solver.message.c_str(), summary.solver.final_residual);
    return kExitNotConverged;
  }
  return kExitOk;
}

}  // namespace rmhb::cli

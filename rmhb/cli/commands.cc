#include "rmhb/cli/commands.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <fstream>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <sstream>

#include "examples/example_system.h"
#include "rmhb/cli/problem_source.h"
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

std::map<std::string, double> ParseOverrides(const std::vector<std::string>& assignments) {
  std::map<std::string, double> values;
  for (const auto& s : assignments) {
    auto [name, v] = ParseAssignment(s);
    values[name] = v;
  }
  return values;
}

void AddSolveOptions(CLI::App* app, SolveArgs* a) {
  app->add_option("model", a->model,
                  "Example name (see `rmhb list`) or model file (examples/models/*.yaml)")
      ->required();
  app->add_option("--set", a->set, "Override a parameter: --set name=value (repeatable)");
  app->add_option("--order,-N,--p", a->order,
                  "Harmonic order: N for one base frequency, p (|m|+|n| <= p) for several "
                  "(default: the model's)");
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
  app->add_option("--eval", a->eval, "Evaluate the solution at t0:dt:t1 (with --csv)");
  app->add_option("--csv", a->csv, "CSV file for --eval: t and every variable");
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

void AddRecastOptions(CLI::App* app, RecastArgs* a) {
  app->add_option("model", a->model, "Example name or model file")->required();
  app->add_option("--set", a->set, "Override a parameter: --set name=value (repeatable)");
  app->add_flag("--json", a->json, "Machine-readable output");
}

int RunRecast(const RecastArgs& a) {
  const std::map<std::string, double> values = ParseOverrides(a.set);
  const ProblemSource source = LoadProblem(a.model, values);
  const PolynomialSystem& sys = source.problem.system;
  if (a.json) {
    json vars = json::array(), eqs = json::array(), conds = json::array();
    for (const auto& v : sys.variables())
      vars.push_back({{"name", v.name},
                      {"role", v.role == VariableRole::kAuxiliary ? "auxiliary" : "state"},
                      {"definition", v.definition}});
    for (const auto& e : sys.equations())
      eqs.push_back({{"equation", e.lhs.ToString(sys.names()) + " = 0"},
                     {"balance_constant", e.balance_constant}});
    for (const auto& c : source.problem.conditions) conds.push_back(c.description);
    json w = json::array();
    for (size_t b = 0; b < source.problem.frequencies.size(); ++b)
      w.push_back({{"value", source.problem.frequencies[b]},
                   {"unknown", !source.problem.unknown_frequency.empty() && source.problem.unknown_frequency[b]}});
    std::cout << json{{"model", source.name}, {"equation", source.equation}, {"degree", sys.Degree()},
                      {"variables", vars}, {"equations", eqs}, {"conditions", conds},
                      {"frequencies", w}}
                     .dump(1)
              << "\n";
  } else {
    std::printf("%s: %s\n\n%s", source.name.c_str(), source.equation.c_str(), source.recast_report.c_str());
    if (!source.from_file && !source.problem.conditions.empty()) {
      std::printf("conditions at t = 0:\n");
      for (const auto& c : source.problem.conditions) std::printf("  %s\n", c.description.c_str());
    }
    std::printf("degree phi = %d: RHB with N harmonics needs M > %d N samples\n", sys.Degree(), sys.Degree() + 1);
  }
  return kExitOk;
}

int RunSolve(const SolveArgs& a) {
  const std::map<std::string, double> values = ParseOverrides(a.set);
  if (a.order != -1 && a.order < 1)
    throw std::invalid_argument("--order must be >= 1 (got " + std::to_string(a.order) + ")");
  if (a.samples != -1 && a.samples < 1)
    throw std::invalid_argument("--samples must be >= 1 (got " + std::to_string(a.samples) + ")");
  ProblemSource source = LoadProblem(a.model, values);
  HarmonicBalanceProblem& problem = source.problem;
  const int bases = static_cast<int>(problem.frequencies.size());
  if (!a.frequencies.empty()) {
    std::vector<std::string> items;
    std::string item;
    for (char c : a.frequencies + ",") {
      if (c == ',') items.push_back(item), item.clear();
      else item += c;
    }
    if (static_cast<int>(items.size()) != bases)
      throw std::invalid_argument("--frequencies: the model has " + std::to_string(bases) +
                                  " base frequencies, got " + std::to_string(items.size()));
    if (problem.unknown_frequency.empty()) problem.unknown_frequency.assign(bases, false);
    for (int b = 0; b < bases; ++b) {
      const bool unknown = !items[b].empty() && items[b][0] == '?';
      const double w = ParseNumberList(unknown ? items[b].substr(1) : items[b], "--frequencies")[0];
      if (!(w > 0)) throw std::invalid_argument("--frequencies: frequencies must be > 0");
      problem.frequencies[b] = w;
      if (unknown) problem.unknown_frequency[b] = true;
    }
  }

  HarmonicBalanceOptions options;
  options.order = a.order > 0 ? a.order : source.default_order;
  options.rule = ParseSamplingRule(a.method);
  if (a.samples > 0) options.samples.assign(bases, a.samples);
  options.allow_aliasing = a.allow_aliasing;
  options.solver.method = ParseSolverMethod(a.solver);
  options.solver.max_iterations = a.max_iterations;
  options.shape = a.shape == "box" ? BasisShape::kBox : BasisShape::kDiamond;
  options.quasi_periodic_sampling =
      a.sampling == "gcd" ? QuasiPeriodicSampling::kGcd : QuasiPeriodicSampling::kTorus;
  // An explicit --basis overrides the example's own index set.
  if (source.basis_for_order && a.shape_given == false) options.basis_for_order = source.basis_for_order;
  HarmonicSolution guess = source.guess(options.order);
  {
    std::vector<double> w = guess.frequencies();
    for (int b = 0; b < bases; ++b) w[b] = problem.frequencies[b];
    guess = guess.WithFrequencies(w);
  }
  const HarmonicBalanceSummary summary = SolveHarmonicBalance(problem, guess, options);
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
  out["alias_free_samples"] = summary.alias_free_samples.size() == 1 ? json(summary.alias_free_samples[0]) : json(summary.alias_free_samples);
  out["sampling"] = summary.sampling;
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
    json harmonics = json::array();
    for (const auto& k : sol.basis().harmonics()) harmonics.push_back(bases == 1 ? json(k[0]) : json(k));
    out["harmonics"] = harmonics;
    out["auxiliary_coefficients"] = aux;
  }
  json reference = json::object();
  if (converged && source.reference.has_frequency())
    reference["frequency_error"] = Number(sol.frequencies()[0] - source.reference.frequency);
  if (converged && source.reference.has_amplitude())
    reference["amplitude_error"] =
        Number(sol.Amplitude(sol.IndexOf(source.reference.amplitude_variable)) -
               source.reference.amplitude);
  if (converged && source.reference.solution) {
    const double T = 2 * M_PI / source.reference.frequency;
    double worst = 0;
    for (int i = 0; i <= 2000; ++i) {
      const double t = T * i / 2000;
      worst = std::max(worst, std::abs(sol.Value(0, t) - source.reference.solution(t)));
    }
    reference["max_error"] = Number(worst);
  }
  if (!reference.empty()) {
    reference["source"] = source.reference.source;
    out["reference"] = reference;
  }
  json validation;
  if (a.validate && converged) {
    if (!source.original) throw std::invalid_argument("cannot validate: " + source.original_error);
    const double period = 2 * M_PI / *std::min_element(sol.frequencies().begin(), sol.frequencies().end());
    const integrators::ValidationReport v = integrators::ValidateTrajectory(
        source.original(sol.frequencies()), [&](double t) { return source.state(sol, t); },
        a.validate_periods * period, source.stiff);
    validation = {{"status", v.ok ? "ok" : "failed"}, {"max_error", Number(v.max_error)},
                  {"periods", a.validate_periods}, {"t_end", a.validate_periods * period},
                  {"seconds", v.seconds}, {"integrator", v.integrator}, {"message", v.message}};
    out["validation"] = validation;
  }
  if (!a.eval.empty() && converged) {
    const std::vector<double> range = ParseNumberList(a.eval, "--eval");
    if (range.size() != 3 || !(range[1] > 0) || range[2] < range[0])
      throw std::invalid_argument("--eval expects t0:dt:t1 with dt > 0 and t1 >= t0");
    const double count = std::floor((range[2] - range[0]) / range[1] + 1e-9) + 1;
    if (count > 5e7) throw std::invalid_argument("--eval: too many points (" + std::to_string(count) + ")");
    if (a.csv.empty()) throw std::invalid_argument("--eval needs --csv FILE");
    std::ofstream csv(a.csv);
    if (!csv) throw std::invalid_argument("--csv: cannot write '" + a.csv + "'");
    csv.precision(17);
    csv << "t";
    for (const auto& v : sol.variables()) csv << "," << v.name;
    csv << "\n";
    for (long i = 0; i < static_cast<long>(count); ++i) {
      const double t = range[0] + i * range[1];
      csv << t;
      for (int j = 0; j < sol.num_variables(); ++j) csv << "," << sol.Value(j, t);
      csv << "\n";
    }
    out["eval"] = {{"file", a.csv}, {"points", static_cast<long>(count)}};
  }

  if (a.json) {
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("%s\n", summary.BriefReport().c_str());
    if (!a.quiet) {
      std::printf("\n%s: %s\n", source.name.c_str(), source.equation.c_str());
      std::printf("recast (phi = %d):\n%s", summary.degree, problem.system.ToString().c_str());
      std::printf("status       %s%s%s\n", out["status"].get<std::string>().c_str(),
                  summary.solver.message.empty() ? "" : ": ", summary.solver.message.c_str());
      std::printf("residual     %.3e after %d iterations (%s)\n", summary.solver.final_residual,
                  summary.solver.iterations, ToString(summary.solver.method));
      std::printf("time         %.3f ms\n", summary.seconds * 1e3);
      if (converged) {
        for (double w : sol.frequencies())
          std::printf("frequency    %.17g  (period %.17g)\n", w, 2 * M_PI / w);
        if (bases > 1) std::printf("harmonics    %d index vectors (%s)\n", sol.basis().size(), sol.basis().shape().c_str());
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
                      reference["frequency_error"].get<double>(), source.reference.source.c_str());
        if (reference.contains("amplitude_error"))
          std::printf("error        amplitude %.3e\n", reference["amplitude_error"].get<double>());
        if (reference.contains("max_error"))
          std::printf("error        max over one period %.3e\n", reference["max_error"].get<double>());
      }
      if (!validation.is_null())
        std::printf("validation   %s: max error %.3e over %d (longest) period(s) against %s (%.1f ms)\n",
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

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
#include "integrators/cvode_integrator.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/cli/plot.h"
#include "rmhb/cli/solve_stability.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/start.h"

namespace rmhb::cli {
using nlohmann::json;

void AddSolveOptions(CLI::App* app, SolveArgs* a) {
  AddSolveSettings(app, &a->settings);
  app->add_option("--start", a->start,
                  "auto (default): the model's guess, and when Newton does not reach a physical solution from "
                  "it, a simulated start (forced models: integrate until the motion settles) or an identified "
                  "one (unknown frequencies); guess: the model's guess only")
      ->check(CLI::IsMember({"auto", "guess"}));
  app->add_option("--eval", a->eval, "Evaluate the solution at t0:dt:t1 (needs --csv)");
  app->add_option("--csv", a->csv, "CSV file for --eval: t and every variable, auxiliaries included");
  app->add_flag("--validate", a->validate,
                "Integrate the original equations with SUNDIALS from the solution's initial "
                "state and report the maximum error");
  app->add_flag("--stability", a->stability,
                "Floquet multipliers of a converged periodic solution by Hill's method and by the "
                "CVODE monodromy matrix of the original equations, their agreement, and the "
                "verdict (stable, unstable, or neutral within 1e-6 of the unit circle); --json: a `stability` object");
  app->add_option("--validate-periods", a->validate_periods, "Periods to integrate (default 1)")
      ->check(CLI::Range(1, 100000));
  app->add_option("--validate-tol", a->validate_tol,
                  "--validate says ok only when the max state error relative to max|state| is at most this "
                  "(default 1e-8); above it: EXCEEDS and exit 6")
      ->check(CLI::PositiveNumber);
  app->add_option("--plot", a->plot,
                  "Draw the time response against a CVODE integration of the original equations, "
                  "their difference and the phase portrait into FILE.png or FILE.svg (gnuplot)");
  app->add_flag("--json", a->json, "Machine-readable output");
  app->add_flag("--quiet,-q", a->quiet, "Only the summary line");
  app->footer(
      "Exit codes: 0 converged, 1 usage, 2 bad input (unknown model or parameter, model file\n"
      "error with file:line:column, invalid value, samples below the alias-free bound without\n"
      "--allow-aliasing, gnuplot missing for --plot), 3 not converged (the residual reached is\n"
      "printed), 4 internal, 5 converged to a NON-PHYSICAL solution (status non_physical, the\n"
      "reason printed: an auxiliary off its definition between the samples -- a wrong root of\n"
      "the recast or aliasing -- or an unknown frequency collapsed to w <= 0; with --continue:\n"
      "some point of the branch is non-physical), 6 --validate measured an error above\n"
      "--validate-tol (relative to max|state|; status exceeds).");
}

void PlotSolution(const ProblemSource& source, const HarmonicSolution& sol, const std::string& file) {
  const double period = 2 * M_PI / *std::min_element(sol.frequencies().begin(), sol.frequencies().end());
  std::vector<double> times(801);
  for (size_t i = 0; i < times.size(); ++i) times[i] = 2 * period * i / (times.size() - 1);
  const int n = source.original ? static_cast<int>(source.state_names.size()) : 0;
  std::vector<std::vector<double>> hb(n, std::vector<double>(times.size()));
  for (size_t i = 0; i < times.size() && n; ++i) {
    const Eigen::VectorXd y = source.state(sol, times[i]);
    for (int j = 0; j < n; ++j) hb[j][i] = y(j);
  }
  PlotPanel response{"time response: harmonic balance (lines) against CVODE (points)", "t", "state", false, false, {}};
  PlotPanel error{"|harmonic balance - CVODE|", "t", "error", false, true, {}};
  PlotPanel phase{"phase portrait", n ? source.state_names[0] : "", n > 1 ? source.state_names[1] : "", false, false, {}};
  if (n) {
    integrators::IntegratorOptions io;
    io.method = source.stiff ? integrators::IntegratorOptions::Method::kBdf : integrators::IntegratorOptions::Method::kAdams;
    io.relative_tolerance = 1e-13;
    io.absolute_tolerance = 1e-15;
    const integrators::IntegrationResult r =
        integrators::IntegrateOde(source.original(sol.frequencies()), source.state(sol, 0.0), 0.0, times, io);
    for (int j = 0; j < n; ++j) {
      PlotSeries line{source.state_names[j] + " (HB)", times, hb[j], PlotSeries::Style::kLines, {}};
      PlotSeries ref{source.state_names[j] + " (CVODE)", {}, {}, PlotSeries::Style::kPoints, {}};
      PlotSeries diff{source.state_names[j], {}, {}, PlotSeries::Style::kLines, {}};
      for (int i = 0; i < r.trajectory.size(); i += 8) ref.x.push_back(r.trajectory.times[i]), ref.y.push_back(r.trajectory.states(i, j));
      for (int i = 0; i < r.trajectory.size(); ++i) {
        diff.x.push_back(r.trajectory.times[i]);
        diff.y.push_back(std::abs(hb[j][i] - r.trajectory.states(i, j)));
      }
      response.series.push_back(line);
      response.series.push_back(ref);
      error.series.push_back(diff);
    }
    if (n > 1) phase.series.push_back({"HB", hb[0], hb[1], PlotSeries::Style::kLines, {}});
  } else {  // no original system: the solution alone
    for (int j = 0; j < sol.num_variables(); ++j) {
      if (sol.variables()[j].role == VariableRole::kAuxiliary) continue;
      PlotSeries line{sol.variables()[j].name, times, {}, PlotSeries::Style::kLines, {}};
      for (double t : times) line.y.push_back(sol.Value(j, t));
      response.series.push_back(line);
    }
    response.title = "time response (no original ODE to compare with: " + source.original_error + ")";
  }
  Plot plot{source.name + ": " + source.equation, {response}};
  if (n) plot.panels.push_back(error);
  if (n > 1) plot.panels.push_back(phase);
  WritePlot(plot, file);
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

void AddRecastOptions(CLI::App* app, RecastArgs* a) {
  app->add_option("model", a->model, "Example name (see `rmhb list`) or model file (examples/models/*.yaml)")
      ->required();
  app->add_option("--set", a->set, "Override a parameter: --set name=value (repeatable)");
  app->add_flag("--json", a->json,
                "Machine-readable output: model, equation, degree, variables (name, role, definition), "
                "equations (with balance_constant), conditions, frequencies");
  app->footer("Exit codes: 0 ok, 1 usage, 2 bad input (unknown example or parameter, model file error\n"
              "with file:line:column), 4 internal.");
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
  if (!a.plot.empty()) CheckPlotRequest(a.plot);
  if (!a.csv.empty() && a.eval.empty())
    throw std::invalid_argument("--csv needs --eval t0:dt:t1 (or --continue, whose branch it writes)");
  PreparedSolve prepared = PrepareSolve(a.settings);
  const ProblemSource& source = prepared.source;
  const HarmonicBalanceProblem& problem = source.problem;
  const HarmonicBalanceOptions& options = prepared.options;
  const HarmonicSolution& guess = prepared.guess;
  const int bases = static_cast<int>(problem.frequencies.size());
  // The guess, else a simulated or identified start (rmhb/pipeline/start.h).
  const StartedSolve started = a.start == "guess" ? StartedSolve{SolveHarmonicBalance(problem, guess, options), "guess", "", 0}
                                                  : SolveFromAnyStart(source, guess, options);
  const HarmonicBalanceSummary& summary = started.summary;
  const HarmonicSolution& sol = *summary.solution;
  const bool converged = summary.converged();

  json out;
  out["model"] = a.settings.model;
  out["status"] = !converged ? ToString(summary.solver.status) : summary.physical ? "converged" : "non_physical";
  out["message"] = summary.solver.message;
  out["start"] = started.route;
  if (!started.note.empty()) out["start_note"] = started.note;
  out["method"] = ToString(options.rule);
  out["solver"] = ToString(summary.solver.method);
  out["order"] = summary.order;
  if (summary.truncation_estimate >= 0)
    out["order_selection"] = {{"tolerance", options.tolerance},
                              {"orders", summary.orders_tried},
                              {"estimate", Number(summary.truncation_estimate)}};
  // null when not computed (the solve failed before a Jacobian was factorised).
  out["reciprocal_condition"] =
      summary.solver.reciprocal_condition > 0 ? Number(summary.solver.reciprocal_condition) : json(nullptr);
  out["scaled_reciprocal_condition"] = summary.solver.scaled_reciprocal_condition > 0
                                           ? Number(summary.solver.scaled_reciprocal_condition)
                                           : json(nullptr);
  out["scaling"] = ToString(summary.solver.scaling);
  out["scaled_residual"] = Number(summary.solver.scaled_residual);
  out["samples"] = summary.samples.size() == 1 ? json(summary.samples[0]) : json(summary.samples);
  out["alias_free_samples"] = summary.alias_free_samples.size() == 1 ? json(summary.alias_free_samples[0]) : json(summary.alias_free_samples);
  out["sampling"] = summary.sampling;
  out["alias_free"] = summary.alias_free;
  out["degree"] = summary.degree;
  out["iterations"] = summary.solver.iterations;
  out["residual"] = Number(summary.solver.final_residual);
  out["seconds"] = summary.seconds;
  out.update(PhysicalJson(summary));
  if (converged) {
    out.update(SolutionJson(sol));
  } else {
    json freqs = json::array();
    for (double w : sol.frequencies()) freqs.push_back(Number(w));
    out["frequencies"] = freqs;
  }
  json reference = json::object();
  if (converged && !source.reference.empty()) {
    const ReferenceErrors e = ErrorsAgainst(source.reference, sol);
    if (source.reference.has_frequency()) reference["frequency_error"] = Number(e.frequency);
    if (source.reference.has_amplitude()) reference["amplitude_error"] = Number(e.amplitude);
    if (source.reference.solution) reference["max_error"] = Number(e.max_error);
  }
  if (!reference.empty()) {
    reference["source"] = source.reference.source;
    out["reference"] = reference;
  }
  json validation;
  if (a.validate && converged) {
    if (!source.original && !source.original_dae)
      throw std::invalid_argument("cannot validate: " + source.original_error);
    const double period = 2 * M_PI / *std::min_element(sol.frequencies().begin(), sol.frequencies().end());
    const integrators::ValidationReport v = ValidateOriginal(source, sol, a.validate_periods * period);
    const ValidationVerdict verdict = JudgeValidation(source, sol, v, a.validate_periods * period, a.validate_tol);
    validation = {{"status", !v.ok ? "failed" : verdict.ok ? "ok" : "exceeds"}, {"max_error", Number(v.max_error)},
                  {"relative_error", Number(verdict.relative_error)}, {"tolerance", a.validate_tol},
                  {"periods", a.validate_periods}, {"t_end", a.validate_periods * period},
                  {"seconds", v.seconds}, {"integrator", v.integrator}, {"message", v.message}};
    out["validation"] = validation;
  }
  if (a.stability && converged) out["stability"] = StabilityJson(source, sol);
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

  if (!a.plot.empty() && converged) {
    PlotSolution(source, sol, a.plot);
    out["plot"] = a.plot;
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
      if (started.route != "guess" || !started.note.empty())
        std::printf("start        %s%s%s\n", started.route.c_str(), started.note.empty() ? "" : "; ", started.note.c_str());
      if (converged) std::printf("physical     %s\n", PhysicalLine(summary).c_str());
      if (summary.truncation_estimate >= 0) {
        std::printf("order        %d %s --tol %g (orders", summary.order,
                    converged ? "chosen for" : "reached, short of", options.tolerance);
        for (int o : summary.orders_tried) std::printf(" %d", o);
        std::printf("), estimated truncation error %.3e\n", summary.truncation_estimate);
      }
      if (summary.solver.reciprocal_condition > 0)
        std::printf("condition    1/cond(J) ~ %.2e (last factorised Jacobian)", summary.solver.reciprocal_condition);
      if (summary.solver.reciprocal_condition > 0 && summary.solver.scaling == Scaling::kEquilibrate)
        std::printf(", equilibrated D_r J D_c ~ %.2e", summary.solver.scaled_reciprocal_condition);
      if (summary.solver.reciprocal_condition > 0) std::printf("\n");
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
    }
    // Asked for by name: printed with --quiet too.
    if (out.contains("stability")) PrintStability(out["stability"]);
    if (!validation.is_null() && validation["max_error"].is_null())
      std::printf("validation   failed: %s integration did not finish: %s (%.1f ms)\n",
                  validation["integrator"].get<std::string>().c_str(),
                  validation["message"].get<std::string>().c_str(),
                  validation["seconds"].get<double>() * 1e3);
    else if (!validation.is_null())
      std::printf("validation   %s: max error %.3e (relative %.2e %s tolerance %.0e) over %d (longest) period(s) "
                  "against %s (%.1f ms)\n",
                  validation["status"] == "ok" ? "ok" : "EXCEEDS", validation["max_error"].get<double>(),
                  validation["relative_error"].get<double>(), validation["status"] == "ok" ? "<=" : ">",
                  a.validate_tol, a.validate_periods, validation["integrator"].get<std::string>().c_str(),
                  validation["seconds"].get<double>() * 1e3);
  }
  if (!converged) {
    if (!a.json)
      std::fprintf(stderr, "rmhb: not converged: %s (max|F| = %.3e)\n",
                   summary.solver.message.c_str(), summary.solver.final_residual);
    return kExitNotConverged;
  }
  if (!summary.physical) {
    if (!a.json)
      std::fprintf(stderr, "rmhb: converged to a NON-PHYSICAL solution (not a solution of the model): %s\n",
                   summary.non_physical.c_str());
    return kExitNonPhysical;
  }
  if (!validation.is_null() && validation["status"] == "exceeds") {
    if (!a.json)
      std::fprintf(stderr, "rmhb: the solution misses its validation tolerance: relative error %.2e > %.0e\n",
                   validation["relative_error"].get<double>(), a.validate_tol);
    return kExitValidationExceeded;
  }
  return kExitOk;
}

}  // namespace rmhb::cli

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
#include "examples/example_model.h"
#include "integrators/trajectory_validation.h"
#include "integrators/cvode_integrator.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/plot/figures.h"
#include "rmhb/plot/plot.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/report.h"
#include "rmhb/pipeline/solve.h"

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
                "verdict (stable, unstable, or neutral within 1e-6 of the unit circle); a torus: Hill's exponents "
                "on the torus and the Lyapunov exponents of the original equations, the verdict on the largest "
                "non-trivial exponent; --json: a `stability` object");
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
  const Model model = examples::LoadModelOrExample(a.model, ParseOverrides(a.set));
  if (a.json) {
    json out = RecastJson(model);
    out["model"] = model.name;
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("%s", RecastReport(model).c_str());
  }
  return kExitOk;
}

namespace {

// --eval t0:dt:t1 into --csv: t and every variable.
json WriteEval(const HarmonicSolution& sol, const SolveArgs& a) {
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
  return {{"file", a.csv}, {"points", static_cast<long>(count)}};
}

int SolveExitCode(const SolveSummary& s, bool quiet) {
  const HarmonicBalanceSummary& hb = s.harmonic_balance;
  switch (s.status) {
    case SolveStatus::kConverged: return kExitOk;
    case SolveStatus::kNotConverged:
      if (!quiet) std::fprintf(stderr, "rmhb: not converged: %s (max|F| = %.3e)\n", hb.solver.message.c_str(), hb.solver.final_residual);
      return kExitNotConverged;
    case SolveStatus::kNonPhysical:
      if (!quiet)
        std::fprintf(stderr, "rmhb: converged to a NON-PHYSICAL solution (not a solution of the model): %s\n",
                     hb.non_physical.c_str());
      return kExitNonPhysical;
    case SolveStatus::kValidationExceeded:
      if (!quiet)
        std::fprintf(stderr, "rmhb: the solution misses its validation tolerance: relative error %.2e > %.0e\n",
                     s.validation->verdict.relative_error, s.validation->verdict.tolerance);
      return kExitValidationExceeded;
  }
  return kExitInternal;
}

}  // namespace

int RunSolve(const SolveArgs& a) {
  if (!a.plot.empty()) plot::CheckPlotRequest(a.plot);
  if (!a.csv.empty() && a.eval.empty())
    throw std::invalid_argument("--csv needs --eval t0:dt:t1 (or --continue, whose branch it writes)");
  ModelSettings settings = a.settings;
  settings.solve.default_tol = SolveSettings::kDefaultTolerance;  // unless --order fixes it
  const PreparedSolve prepared = Prepare(settings);
  SolveOptions options;
  options.harmonic_balance = prepared.options;
  options.auto_start = a.start == "auto";
  options.validate = a.validate;
  options.validate_periods = a.validate_periods;
  options.validate_tolerance = a.validate_tol;
  options.stability = a.stability;
  const SolveSummary summary = SolveModel(prepared.model, prepared.guess, options);
  json out = summary.ToJson();
  out["model"] = a.settings.model;
  if (!a.eval.empty() && summary.converged()) out["eval"] = WriteEval(summary.solution(), a);
  if (!a.plot.empty() && summary.converged()) {
    // SolveModel may have fallen back on the original equations.
    const bool fell_back = summary.equations != prepared.model.equations && prepared.model.original_equations;
    plot::PlotSolution(fell_back ? prepared.model.original_equations() : prepared.model, summary.solution(), a.plot);
    out["plot"] = a.plot;
  }
  if (a.json)
    std::cout << out.dump(1) << "\n";
  else if (a.quiet)
    std::printf("%s\n%s", summary.BriefReport().c_str(), summary.RequestedReport().c_str());
  else
    std::printf("%s", summary.FullReport().c_str());
  return SolveExitCode(summary, a.json);
}

}  // namespace rmhb::cli

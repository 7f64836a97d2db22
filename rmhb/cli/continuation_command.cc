#include "rmhb/cli/continuation_command.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>

#include "integrators/trajectory_validation.h"
#include "rmhb/cli/branch_plot.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/cli/plot.h"
#include "rmhb/cli/solve_setup.h"
#include "rmhb/continuation.h"
#include "rmhb/definition_check.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;

struct Range {
  std::string name;
  double from, to;
};

Range ParseRange(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument("--continue expects NAME=a:b, got '" + text + "'");
  const std::vector<double> ends = ParseNumberList(text.substr(eq + 1), "--continue");
  if (ends.size() != 2 || text.find(',', eq) != std::string::npos)
    throw std::invalid_argument("--continue expects NAME=a:b (two numbers), got '" + text + "'");
  if (ends[0] == ends[1])
    throw std::invalid_argument("--continue " + text + ": the range is empty (a = b)");
  return {text.substr(0, eq), ends[0], ends[1]};
}

// max |x(t)| of the first variable: over one period, or for a quasi-periodic
// solution over many periods of the slowest base (a lower bound of the sup).
double PeakValue(const HarmonicSolution& s) {
  if (s.frequencies().size() == 1) return s.Amplitude(0);
  const double w = *std::min_element(s.frequencies().begin(), s.frequencies().end());
  const double span = 200 * 2 * M_PI / w;
  double peak = 0;
  for (int i = 0; i < 20000; ++i) peak = std::max(peak, std::abs(s.Value(0, span * i / 20000)));
  return peak;
}

struct PointReport {
  double peak = 0;
  std::string stability;           // stable, unstable, neutral or unknown
  double validation_error = NAN;   // with --validate
  // Against the model's exact reference at this parameter value, if any.
  double frequency_error = NAN, amplitude_error = NAN;
  std::optional<DefinitionCheck> definitions;  // when the model has auxiliaries
  double reference_error() const {
    return std::isnan(frequency_error) ? std::abs(amplitude_error)
           : std::isnan(amplitude_error) ? std::abs(frequency_error)
                                         : std::max(std::abs(frequency_error), std::abs(amplitude_error));
  }
};

}  // namespace

void AddContinuationOptions(CLI::App* app, ContinuationArgs* a) {
  app->add_option("--continue", a->range,
                  "Follow the branch as parameter NAME goes from a to b (NAME=a:b, any --set-able "
                  "parameter, e.g. w=0.5:3): prints parameter, frequency, amplitude max|x| of the "
                  "first variable, residual and stability per point, and marks folds. --csv FILE "
                  "writes the branch");
  app->add_option("--steps", a->steps,
                  "Continuation: first step |b - a| / K (default 20); the step then adapts")
      ->check(CLI::Range(1, 1000000));
  app->add_option("--max-step", a->max_step,
                  "Continuation: largest step, arclength in (coefficients, parameter) or the "
                  "parameter with --natural (default |b - a| / 10, or the first step if larger)")
      ->check(CLI::PositiveNumber);
  app->add_flag("--natural", a->natural,
                "Continuation: natural-parameter steps (stop at a fold) instead of "
                "pseudo-arclength (passes folds)");
  app->add_option("--plot-var", a->plot_var,
                  "Continuation with --plot: draw the amplitude max|VAR(t)| of this variable (default: the "
                  "first) or, with 'frequency', the first base frequency against the parameter");
  app->add_flag("--no-stability", a->no_stability,
                "Continuation: skip Hill's method per point (one eigenproblem of the Jacobian's "
                "size each; computed by default up to 200 unknowns)");
}

int RunContinuation(const SolveArgs& solve, const ContinuationArgs& a) {
  const Range range = ParseRange(a.range);
  if (!solve.eval.empty()) throw std::invalid_argument("--eval does not apply to --continue");
  if (!solve.plot.empty()) CheckPlotRequest(solve.plot);
  if (solve.start != "auto") throw std::invalid_argument("--start applies to one solve, not to --continue");
  if (!a.plot_var.empty() && solve.plot.empty()) throw std::invalid_argument("--plot-var needs --plot");
  if (solve.stability && a.no_stability)
    throw std::invalid_argument("--stability and --no-stability contradict each other (continuation reports "
                                "stability at every point by default)");
  // Both ends must be values the model accepts (bad input, not a failed step).
  PreparedSolve prepared = PrepareSolve(solve.settings, {{range.name, range.from}});
  try {
    LoadSolveProblem(solve.settings, {{range.name, range.to}});
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("--continue " + a.range + ": at the end of the range: " + e.what());
  }

  ContinuationProblem problem;
  problem.parameter = range.name;
  problem.start = range.from;
  problem.end = range.to;
  problem.build = [&](double value) {
    return LoadSolveProblem(solve.settings, {{range.name, value}}).problem;
  };
  ContinuationOptions options;
  options.method = a.natural ? ContinuationMethod::kNatural : ContinuationMethod::kPseudoArclength;
  options.harmonic_balance = prepared.options;
  options.stability = !a.no_stability;
  options.initial_step = std::abs(range.to - range.from) / a.steps;
  options.max_step = a.max_step > 0 ? a.max_step
                                    : std::max(options.initial_step, std::abs(range.to - range.from) / 10);
  options.initial_step = std::min(options.initial_step, options.max_step);
  const ContinuationSummary summary = TraceBranch(problem, prepared.guess, options);

  std::vector<PointReport> reports;
  for (const ContinuationPoint& p : summary.points) {
    PointReport r;
    r.peak = PeakValue(p.solution);
    r.stability = ToString(p.stability);
    const ProblemSource source = LoadSolveProblem(solve.settings, {{range.name, p.parameter}});
    if (source.problem.definitions)
      r.definitions = CheckDefinitions(p.solution, source.problem.definitions, summary.samples);
    const ReferenceErrors errors = ErrorsAgainst(source.reference, p.solution);
    r.frequency_error = errors.frequency;
    r.amplitude_error = errors.amplitude;
    if (solve.validate) {
      const auto& w = p.solution.frequencies();
      const double period = 2 * M_PI / *std::min_element(w.begin(), w.end());
      const integrators::ValidationReport v = ValidateOriginal(source, p.solution, solve.validate_periods * period, 401);
      r.validation_error = v.ok ? v.max_error : NAN;
    }
    reports.push_back(r);
  }

  const bool has_reference = prepared.source.reference.has_frequency() ||
                             prepared.source.reference.has_amplitude();
  json branch = json::array();
  json folds = json::array();
  std::vector<size_t> non_physical;  // points whose auxiliaries are off their definitions
  for (size_t i = 0; i < summary.points.size(); ++i) {
    const ContinuationPoint& p = summary.points[i];
    json w = json::array();
    for (double v : p.solution.frequencies()) w.push_back(Number(v));
    json point = {{"parameter", Number(p.parameter)}, {"frequencies", w},
                  {"amplitude", Number(reports[i].peak)}, {"residual", Number(p.residual)},
                  {"iterations", p.iterations}, {"arclength", Number(p.arclength)},
                  {"fold", p.fold}, {"stability", reports[i].stability}};
    if (solve.validate) point["validation_error"] = Number(reports[i].validation_error);
    if (has_reference)
      point["reference"] = {{"frequency_error", Number(reports[i].frequency_error)},
                            {"amplitude_error", Number(reports[i].amplitude_error)}};
    if (const auto& c = reports[i].definitions) {
      point["physical"] = c->physical;
      point["definition_error"] = Number(c->error);
      point["definition_worst"] = c->worst_variable;
      if (!c->physical) non_physical.push_back(i);
    }
    if (p.fold) folds.push_back(Number(p.parameter));
    branch.push_back(point);
  }
  const int code = !(summary.completed() || summary.status == ContinuationStatus::kLeftRange)
                       ? kExitNotConverged
                       : non_physical.empty() ? kExitOk : kExitNonPhysical;

  if (!solve.csv.empty()) {
    std::ofstream csv(solve.csv);
    if (!csv) throw std::invalid_argument("--csv: cannot write '" + solve.csv + "'");
    csv.precision(17);
    csv << range.name;
    for (size_t b = 0; b < prepared.source.problem.frequencies.size(); ++b) csv << ",w" << b + 1;
    csv << ",amplitude,residual,fold,stability" << (solve.validate ? ",validation_error" : "")
        << (has_reference ? ",frequency_error,amplitude_error" : "") << "\n";
    for (size_t i = 0; i < summary.points.size(); ++i) {
      const ContinuationPoint& p = summary.points[i];
      csv << p.parameter;
      for (double v : p.solution.frequencies()) csv << "," << v;
      csv << "," << reports[i].peak << "," << p.residual << "," << (p.fold ? 1 : 0) << ","
          << reports[i].stability;
      if (solve.validate) csv << "," << reports[i].validation_error;
      if (has_reference) csv << "," << reports[i].frequency_error << "," << reports[i].amplitude_error;
      csv << "\n";
    }
  }

  std::string plot_data;
  if (!solve.plot.empty() && !summary.points.empty()) {
    const std::string var = a.plot_var.empty() ? summary.points[0].solution.variables()[0].name : a.plot_var;
    const std::vector<BranchRow> rows = BranchRows(summary, var);
    plot_data = solve.plot + ".dat";
    WriteBranchData(rows, range.name, var, plot_data);
    PlotBranch(rows, prepared.source.name + ": " + prepared.source.equation, range.name, var, solve.plot);
  }

  if (solve.json) {
    json out = {{"model", solve.settings.model},
                {"parameter", range.name},
                {"range", {Number(range.from), Number(range.to)}},
                {"method", ToString(summary.method)},
                {"status", ToString(summary.status)},
                {"message", summary.message},
                {"stability_note", summary.stability_note},
                {"order", summary.order},
                {"samples", summary.samples.size() == 1 ? json(summary.samples[0]) : json(summary.samples)},
                {"points", summary.points.size()},
                {"folds", folds},
                {"accepted_steps", summary.accepted_steps},
                {"rejected_steps", summary.rejected_steps},
                {"arclength", Number(summary.arclength)},
                {"seconds", summary.seconds},
                {"branch", branch}};
    if (!solve.csv.empty()) out["csv"] = solve.csv;
    if (!plot_data.empty()) out["plot"] = solve.plot, out["plot_data"] = plot_data;
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("%s\n", summary.BriefReport().c_str());
    if (!summary.message.empty()) std::printf("%s\n", summary.message.c_str());
    if (!summary.stability_note.empty()) std::printf("stability unknown: %s\n", summary.stability_note.c_str());
    // --quiet hides the table unless it holds what --validate or
    // --stability asked for.
    if (!solve.quiet || solve.validate || solve.stability) {
      std::printf("\n%-22s %-20s %-20s %-9s %-9s%s%s\n", range.name.c_str(), "frequency",
                  "amplitude max|x|", "residual", "stability", solve.validate ? " validation" : "",
                  has_reference ? " exact error" : "");
      for (size_t i = 0; i < summary.points.size(); ++i) {
        const ContinuationPoint& p = summary.points[i];
        std::string w;
        for (double v : p.solution.frequencies()) {
          char text[32];
          std::snprintf(text, sizeof text, "%s%.15g", w.empty() ? "" : ",", v);
          w += text;
        }
        std::printf("%-22.15g %-20s %-20.15g %-9.1e %-9s", p.parameter, w.c_str(), reports[i].peak,
                    p.residual, reports[i].stability.c_str());
        if (solve.validate) std::printf(" %-10.1e", reports[i].validation_error);
        if (has_reference) std::printf(" %.1e", reports[i].reference_error());
        std::printf("%s%s\n", p.fold ? "  <- fold" : "",
                    reports[i].definitions && !reports[i].definitions->physical ? "  <- NON-PHYSICAL" : "");
      }
    }
  }
  for (size_t i : non_physical)
    if (!solve.json)
      std::fprintf(stderr, "rmhb: NON-PHYSICAL point %s = %.15g: %s\n", range.name.c_str(),
                   summary.points[i].parameter, reports[i].definitions->Report().c_str());
  if (code != kExitOk && !solve.json)
    std::fprintf(stderr, "rmhb: continuation stopped: %s\n", summary.message.c_str());
  return code;
}

}  // namespace rmhb::cli

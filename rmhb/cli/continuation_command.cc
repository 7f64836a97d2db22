#include "rmhb/cli/commands.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>

#include "rmhb/plot/branch_plot.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/plot/figures.h"
#include "rmhb/plot/plot.h"
#include "rmhb/pipeline/branch.h"

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

}  // namespace

void AddContinuationOptions(CLI::App* app, ContinuationArgs* a) {
  app->add_option("--continue", a->range,
                  "Follow the branch as parameter NAME goes from a to b (NAME=a:b, any --set-able "
                  "parameter, e.g. w=0.5:3): prints parameter, frequency, amplitude max|x| of the "
                  "first variable, residual, stability and the largest Floquet multiplier per point, "
                  "and marks folds, branch points (BP), period doublings (PD) and Neimark-Sacker "
                  "points (NS), each located. --csv FILE writes the branch");
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
                  "first), with 'frequency' the first base frequency, with 'ratio' (default for tori) the "
                  "rotation number w2/w1 (the devil's staircase, locked branches at p/q) against the parameter");
  app->add_flag("--no-stability", a->no_stability,
                "Continuation: skip the Floquet multipliers per point (and so the bifurcations but folds)");
  app->add_option("--stability-method", a->stability_method,
                  "Continuation: auto (default: the monodromy of the harmonic balance linearisation where it "
                  "applies (an ODE without recast auxiliaries), else Hill's method up to 40 unknowns, else the "
                  "monodromy of the original equations by CVODE/IDA; all applicable at the first point, "
                  "compared), hb-monodromy, hill or monodromy")
      ->check(CLI::IsMember({"auto", "hill", "monodromy", "hb-monodromy"}))
      ->each([a](const std::string&) { a->stability_method_given = true; });
  app->add_option("--torus-tail", a->torus_tail,
                  "Continuation of a quasi-periodic model: where the torus' outermost coefficients exceed this "
                  "fraction of the solution (default 1e-6: the basis no longer resolves it), enrich the adaptive "
                  "index set there and go on, or stop on a fixed basis (--p)")
      ->check(CLI::PositiveNumber)
      ->each([a](const std::string&) { a->torus_tail_given = true; });
  app->add_flag("--no-locking", a->no_locking,
                "Continuation of a quasi-periodic model: stop where the torus stops instead of crossing "
                "the locking tongue ahead (the locked orbit of base w1/q followed to both edges, the torus "
                "resumed past it)");
  app->add_flag("--switch-branches", a->switch_branches,
                "Continuation: from every period doubling follow the period-2T branch, and at every "
                "Neimark-Sacker point solve the torus just past it (two bases: the forcing and "
                "w2 = w arg(mu)/2pi), validated against CVODE");
}

void CheckWithoutContinuation(const ContinuationArgs& a) {
  if (a.switch_branches) throw std::invalid_argument("--switch-branches needs --continue");
  if (a.stability_method_given) throw std::invalid_argument("--stability-method needs --continue");
  if (a.torus_tail_given) throw std::invalid_argument("--torus-tail needs --continue");
  if (a.no_locking) throw std::invalid_argument("--no-locking needs --continue");
}

namespace {

// Rows of one branch: `index` 0 the traced one, k the k-th period-2T branch.
void CsvRows(const BranchSummary& b, const ContinuationSummary& c, const std::vector<BranchPointReport>& reports,
             int index, std::ofstream& csv) {
  for (size_t i = 0; i < c.points.size(); ++i) {
    const ContinuationPoint& p = c.points[i];
    const BranchPointReport& r = reports[i];
    csv << p.parameter;
    for (double v : p.solution.frequencies()) csv << "," << v;
    csv << "," << r.peak << "," << p.residual << "," << (p.fold ? 1 : 0) << "," << r.stability;
    if (b.validated) csv << "," << r.validation_error;
    if (b.has_reference) csv << "," << r.frequency_error << "," << r.amplitude_error;
    if (b.bases > 1)
      csv << "," << r.ratio << "," << r.outermost << ","
          << (r.lyapunov && r.lyapunov->ok ? r.lyapunov->max_exponent : NAN) << "," << r.segment;
    csv << "," << ToString(p.stability_method) << "," << p.max_multiplier << ","
        << (p.bifurcation >= 0 ? ToString(c.bifurcations[p.bifurcation].type) : "") << "," << index << "\n";
  }
}

void WriteCsv(const BranchSummary& b, const std::string& file) {
  std::ofstream csv(file);
  if (!csv) throw std::invalid_argument("--csv: cannot write '" + file + "'");
  csv.precision(17);
  csv << b.continuation.parameter;
  for (int i = 0; i < b.bases; ++i) csv << ",w" << i + 1;
  csv << ",amplitude,residual,fold,stability" << (b.validated ? ",validation_error" : "")
      << (b.has_reference ? ",frequency_error,amplitude_error" : "")
      << (b.bases > 1 ? ",ratio,outermost,max_lyapunov_exponent,stretch" : "") << ",stability_method,max_multiplier,bifurcation,branch\n";
  CsvRows(b, b.continuation, b.reports, 0, csv);
  int index = 0;
  for (const DoubledBranchReport& d : b.doubled)
    if (d.branch.branch) CsvRows(b, *d.branch.branch, d.reports, ++index, csv);
}

}  // namespace

int RunContinuation(const SolveArgs& solve, const ContinuationArgs& a) {
  const Range range = ParseRange(a.range);
  if (!solve.eval.empty()) throw std::invalid_argument("--eval does not apply to --continue");
  if (!solve.plot.empty()) plot::CheckPlotRequest(solve.plot);
  if (solve.start != "auto") throw std::invalid_argument("--start applies to one solve, not to --continue");
  if (!a.plot_var.empty() && solve.plot.empty()) throw std::invalid_argument("--plot-var needs --plot");
  if (solve.stability && a.no_stability)
    throw std::invalid_argument("--stability and --no-stability contradict each other (continuation reports "
                                "stability at every point by default)");
  if (a.no_stability && (a.stability_method_given || a.switch_branches))
    throw std::invalid_argument(std::string(a.switch_branches ? "--switch-branches" : "--stability-method") +
                                " needs the stability that --no-stability turns off");
  if (a.natural && a.switch_branches)
    throw std::invalid_argument("--switch-branches follows the new branches by pseudo-arclength: drop --natural");
  ModelSettings settings = solve.settings;
  settings.solve.default_torus_tol = SolveSettings::kDefaultTolerance;  // tori: the first point's index set
  const PreparedSolve prepared = Prepare(settings, {{range.name, range.from}});
  ContinueOptions options;
  options.parameter = range.name;
  options.from = range.from;
  options.to = range.to;
  options.harmonic_balance = prepared.options;
  options.steps = a.steps;
  options.max_step = a.max_step;
  options.natural = a.natural;
  options.stability = !a.no_stability;
  options.stability_method = ParseStabilityMethod(a.stability_method);
  options.switch_branches = a.switch_branches;
  options.validate_tolerance = solve.validate_tol;
  options.validate = solve.validate;
  options.validate_periods = solve.validate_periods;
  options.tail_tolerance = a.torus_tail;
  options.locking = !a.no_locking;
  BranchSummary branch;
  try {
    branch = ContinueModel(prepared.model, prepared.guess, options);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("--continue " + a.range + ": " + e.what());
  }
  const ContinuationSummary& summary = branch.continuation;
  if (!solve.csv.empty()) WriteCsv(branch, solve.csv);
  std::string plot_data;
  if (!solve.plot.empty() && !summary.points.empty()) {
    const std::string var = !a.plot_var.empty() ? a.plot_var
                            : branch.bases == 2 ? "ratio"
                                                : summary.points[0].solution.variables()[0].name;
    std::vector<plot::BranchRow> rows = plot::BranchRows(summary, var);
    for (size_t i = 0; i < rows.size(); ++i) rows[i].stability = branch.reports[i].stability;  // tori: Lyapunov's
    int index = 0;
    for (const DoubledBranchReport& d : branch.doubled)
      if (d.branch.branch) {
        const std::vector<plot::BranchRow> more = plot::BranchRows(*d.branch.branch, var, ++index);
        rows.insert(rows.end(), more.begin(), more.end());
      }
    if (var == "ratio")
      for (const TongueReport& t : branch.tongues)
        for (const ContinuationSummary& l : t.locked) {
          const std::vector<plot::BranchRow> more =
              plot::LockedRows(l, static_cast<double>(t.lock.p) / t.lock.q, ++index);
          rows.insert(rows.end(), more.begin(), more.end());
        }
    plot_data = solve.plot + ".dat";
    plot::WriteBranchData(rows, range.name, var, plot_data);
    plot::PlotBranch(rows, prepared.model.name + ": " + prepared.model.equation, range.name, var, solve.plot);
  }
  if (solve.json) {
    json out = branch.ToJson();
    out["model"] = solve.settings.model;
    if (!solve.csv.empty()) out["csv"] = solve.csv;
    if (!plot_data.empty()) out["plot"] = solve.plot, out["plot_data"] = plot_data;
    std::cout << out.dump(1) << "\n";
    return branch.status == BranchStatus::kCompleted     ? kExitOk
           : branch.status == BranchStatus::kNonPhysical ? kExitNonPhysical
                                                         : kExitNotConverged;
  }
  // --quiet hides the table unless it holds what --validate or --stability asked for.
  std::printf("%s", branch.FullReport(!solve.quiet || solve.validate || solve.stability).c_str());
  for (size_t i : branch.non_physical)
    std::fprintf(stderr, "rmhb: NON-PHYSICAL point %s = %.15g: %s\n", range.name.c_str(),
                 summary.points[i].parameter, branch.reports[i].definitions->Report().c_str());
  if (branch.status == BranchStatus::kCompleted) return kExitOk;
  if (branch.status == BranchStatus::kSwitchFailed) {
    std::fprintf(stderr, "rmhb: %s\n", branch.message.c_str());
    return kExitNotConverged;
  }
  std::fprintf(stderr, "rmhb: continuation stopped: %s\n", summary.message.c_str());
  return branch.status == BranchStatus::kStopped ? kExitNotConverged : kExitNonPhysical;
}

}  // namespace rmhb::cli

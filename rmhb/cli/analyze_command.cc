#include "rmhb/cli/analyze_command.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "rmhb/seeding/identified_guess.h"
#include "frequency_id/frequency_identification.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/cli/commands.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/cli/plot.h"
#include "rmhb/pipeline/analyze.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

bool Unknown(const HarmonicBalanceProblem& p, int b) {
  return !p.unknown_frequency.empty() && p.unknown_frequency[b];
}

}  // namespace

void AddAnalyzeOptions(CLI::App* app, AnalyzeArgs* a) {
  AddSolveSettings(app, &a->settings);
  app->add_option("--t-end", a->t_end,
                  "End of the integrated record for identification (default: 60 periods for one base; "
                  "for several 200 periods of the slowest base or 3 beats of the closest pair, whichever is longer, plus the transient)")
      ->check(CLI::NonNegativeNumber);
  app->add_option("--transient", a->transient, "Initial time integrated but not recorded (default: a tenth of --t-end)")
      ->check(CLI::NonNegativeNumber);
  app->add_option("--samples-per-period", a->samples_per_period,
                  "Record samples per period of the fastest base (default: 2.5 N for one base, "
                  "within [16, 1024]; 12 for several)")
      ->check(CLI::Range(0, 4096));
  app->add_option("--window", a->window, "Hann^q window order q for identification (0: automatic)")
      ->check(CLI::Range(0, 8));
  app->add_option("--validate-tol", a->validate_tol,
                  "The validation passes when the max state error relative to max|state| is at most this "
                  "(default 1e-8); above it: EXCEEDS and exit 6")
      ->check(CLI::PositiveNumber);
  app->add_option("--validate-periods", a->validate_periods,
                  "Validate over this many periods of the slowest base (default 20)")
      ->check(CLI::Range(1, 100000));
  app->add_option("--plot", a->plot,
                  "Draw two periods of the solution against CVODE started on it, their difference "
                  "and the phase portrait into FILE.png or FILE.svg (gnuplot)");
  app->add_flag("--json", a->json, "Machine-readable output");
}

namespace {

// The stages of the record, identification and seed as JSON and text lines.
void ReportIdentification(const Model& source, const AnalyzeSummary& s, json* stages,
                          std::vector<std::string>* lines) {
  char text[512];
  const seeding::RecordOptions& record = s.trajectory->record;
  std::snprintf(text, sizeof text, "%-10s %9.1f ms  %s rtol %.0e: %d samples, t in [%g, %g], dt %.4g", "trajectory",
                s.trajectory->seconds * 1e3, OriginalIntegrator(source), record.integrator.relative_tolerance,
                s.trajectory->samples, record.transient, record.t_end, record.dt);
  lines->push_back(text + (s.trajectory->settle_periods > 0
                               ? " after the motion settled (" + std::to_string(s.trajectory->settle_periods) +
                                     " periods)"
                               : std::string()));
  (*stages)["trajectory"] = {{"seconds", s.trajectory->seconds}, {"samples", s.trajectory->samples},
                             {"transient", record.transient}, {"t_end", record.t_end}, {"dt", record.dt},
                             {"relative_tolerance", record.integrator.relative_tolerance},
                             {"settle_periods", s.trajectory->settle_periods}};
  if (!s.identification) return;
  const frequency_id::IdentificationSummary& id = *s.identification;
  (*stages)["identify"] = {{"seconds", s.identify_seconds}, {"status", ToString(id.status)}, {"message", id.message},
                           {"window_order", id.window_order}, {"lines", id.components.size()},
                           {"explained", id.num_explained}};
  std::snprintf(text, sizeof text, "%-10s %9.1f ms  %s, %zu lines (%d explained), Hann^%d, bases", "identify",
                s.identify_seconds * 1e3, ToString(id.status), id.components.size(), id.num_explained,
                id.window_order);
  // The bases as selected (any basis of the lattice); the seed maps them to the model's.
  json selected = json::array();
  std::string report = text;
  for (size_t i = 0; i < id.bases.size(); ++i) {
    selected.push_back(Number(id.bases[i].frequency));
    std::snprintf(text, sizeof text, "%s b%zu = %.12g", i ? "," : "", i + 1, id.bases[i].frequency);
    report += text;
  }
  (*stages)["identify"]["selected_bases"] = selected;
  lines->push_back(report);
  if (!s.seed) return;
  const seeding::IdentifiedGuess& seed = *s.seed;
  json identified = json::array();
  for (size_t b = 0; b < seed.frequencies.size(); ++b)
    identified.push_back({{"frequency", Number(seed.frequencies[b])},
                          {"uncertainty", Number(seed.uncertainties[b])},
                          {"known", !Unknown(source.problem, static_cast<int>(b))}});
  (*stages)["identify"]["bases"] = identified;
  (*stages)["seed"] = {{"seconds", s.seed_seconds}, {"lines_used", seed.lines_used},
                       {"lines_dropped", seed.lines_dropped}, {"energy_on_basis", Number(seed.energy_on_basis)},
                       {"fitted_harmonics", seed.fitted_harmonics}, {"coordinates", seed.coordinates},
                       {"phase_shift", seed.phase_shift}, {"condition_residual", Number(seed.condition_residual)}};
  std::snprintf(text, sizeof text, "%-10s %9.1f ms  ", "seed", s.seed_seconds * 1e3);
  lines->push_back(text + seed.Report());
}

void ReportSolve(const AnalyzeSummary& s, const HarmonicBalanceOptions& options, json* stages,
                 std::vector<std::string>* lines) {
  const HarmonicBalanceSummary& summary = *s.solve;
  const bool converged = summary.converged();
  const int bases = static_cast<int>(s.problem.frequencies.size());
  const int unknowns =
      summary.solution ? summary.solution->num_variables() * summary.solution->basis().num_coefficients() : 0;
  (*stages)["solve"] = {{"seconds", summary.seconds}, {"status", converged ? "converged" : ToString(summary.solver.status)},
                        {"iterations", summary.solver.iterations}, {"residual", Number(summary.solver.final_residual)},
                        {"method", ToString(options.rule)}, {"solver", ToString(summary.solver.method)},
                        {"order", options.order}, {"harmonics", summary.solution ? summary.solution->basis().size() : 0},
                        {"coefficients", unknowns}, {"alias_free", summary.alias_free}, {"degree", summary.degree},
                        {"samples", summary.samples.size() == 1 ? json(summary.samples[0]) : json(summary.samples)}};
  char text[512];
  std::snprintf(text, sizeof text, "%-10s %9.1f ms  %s %s order %d: %s after %d iterations, max|F| %.3e", "solve",
                summary.seconds * 1e3, bases == 1 ? "RHB" : "RMHB", ToString(options.rule), options.order,
                converged ? "converged" : "NOT converged", summary.solver.iterations, summary.solver.final_residual);
  lines->push_back(text);
  (*stages)["solve"].update(PhysicalJson(summary));
  if (converged) lines->push_back("physical" + std::string(17, ' ') + PhysicalLine(summary));
  if (!converged || !stages->contains("identify") || !(*stages)["identify"].contains("bases")) return;
  const std::vector<double>& w = summary.solution->frequencies();
  for (int b = 0; b < bases; ++b) {
    json& base = (*stages)["identify"]["bases"][b];
    base["solved"] = Number(w[b]);
    base["difference"] = Number(w[b] - base["frequency"].get<double>());
    std::snprintf(text, sizeof text, "%-10s w%d identified %.15g +- %.1e, solved %.15g, difference %+.2e%s", "",
                  b + 1, base["frequency"].get<double>(), base["uncertainty"].get<double>(), w[b],
                  w[b] - base["frequency"].get<double>(), Unknown(s.problem, b) ? "" : " (known)");
    lines->push_back(text);
  }
}

void ReportValidation(const AnalyzeSummary& s, int periods, json* stages, std::vector<std::string>* lines) {
  const integrators::ValidationReport& v = *s.validation;
  const bool within = s.verdict && s.verdict->ok;
  (*stages)["validate"] = {{"seconds", v.seconds}, {"status", !v.ok ? "failed" : within ? "ok" : "exceeds"},
                           {"max_error", Number(v.max_error)}, {"t_end", s.validation_t_end},
                           {"relative_error", Number(s.verdict ? s.verdict->relative_error : NAN)},
                           {"tolerance", s.verdict ? s.verdict->tolerance : NAN},
                           {"periods", periods}, {"integrator", v.integrator}, {"message", v.message}};
  char text[512];
  std::snprintf(text, sizeof text, "%-10s %9.1f ms  %s: max error %.3e (relative %.2e, tolerance %.0e) over t in [0, %g] against %s",
                "validate", v.seconds * 1e3, !v.ok ? "FAILED" : within ? "ok" : "EXCEEDS", v.max_error,
                s.verdict ? s.verdict->relative_error : NAN, s.verdict ? s.verdict->tolerance : NAN,
                s.validation_t_end, v.integrator.c_str());
  lines->push_back(text + (v.message.empty() ? std::string() : " (" + v.message + ")"));
}

int ExitCode(AnalyzeStatus status) {
  switch (status) {
    case AnalyzeStatus::kConverged: return kExitOk;
    case AnalyzeStatus::kNonPhysical: return kExitNonPhysical;
    case AnalyzeStatus::kValidationExceeded: return kExitValidationExceeded;
    default: return kExitNotConverged;
  }
}

}  // namespace

int RunAnalyze(const AnalyzeArgs& a) {
  const auto start = Clock::now();
  const PreparedSolve prepared = PrepareSolve(a.settings);
  const ProblemSource& source = prepared.source;
  if (!a.plot.empty()) CheckPlotRequest(a.plot);
  AnalyzeOptions options;
  options.solve = prepared.options;
  options.identify = a.settings.frequencies.empty();
  options.t_end = a.t_end;
  options.transient = a.transient;
  options.samples_per_period = a.samples_per_period;
  options.window = a.window;
  options.validate_periods = a.validate_periods;
  options.validate_tolerance = a.validate_tol;
  // The library says t_end and transient; the user wrote the options.
  if (!std::isfinite(a.t_end) || !std::isfinite(a.transient))
    throw std::invalid_argument("--t-end and --transient must be finite numbers");
  if (a.t_end > 1e7 || a.transient > 1e7) throw std::invalid_argument("--t-end is too large (at most 1e7)");
  if (a.t_end > 0 && a.transient >= a.t_end)
    throw std::invalid_argument("--transient must be shorter than --t-end");
  const AnalyzeSummary s = Analyze(source, options);

  json stages = json::object();
  std::vector<std::string> lines;  // the text report, one per stage
  if (s.trajectory) ReportIdentification(source, s, &stages, &lines);
  if (s.solve) ReportSolve(s, options.solve, &stages, &lines);
  if (s.validation) ReportValidation(s, a.validate_periods, &stages, &lines);
  const int exit_code = ExitCode(s.status);
  const std::string status = s.status == AnalyzeStatus::kNotConverged ? ToString(s.solve->solver.status)
                                                                       : ToString(s.status);
  const double total = Since(start);
  json out;
  out["model"] = a.settings.model;
  out["status"] = status;
  out["message"] = s.message;
  out["identified"] = s.identified;
  out["stages"] = stages;
  out["seconds"] = total;
  const bool solved = exit_code == kExitOk || exit_code == kExitValidationExceeded;
  if (solved) out.update(SolutionJson(*s.solve->solution));
  if (solved && !a.plot.empty()) {
    PlotSolution(source, *s.solve->solution, a.plot);
    out["plot"] = a.plot;
  }

  if (a.json) {
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("analyze %s: %s\n", source.name.c_str(), source.equation.c_str());
    for (const auto& l : lines) std::printf("%s\n", l.c_str());
    std::printf("%-10s %9.1f ms  (everything, model loading included)\n", "total", total * 1e3);
    if (solved)
      for (double w : s.solve->solution->frequencies()) std::printf("frequency  %.17g  (period %.17g)\n", w, 2 * M_PI / w);
  }
  if (exit_code != kExitOk && !a.json)
    std::fprintf(stderr, "rmhb: analyze: %s: %s%s\n", status.c_str(), s.message.c_str(),
                 s.solve ? (" (max|F| = " + std::to_string(s.solve->solver.final_residual) + ")").c_str() : "");
  return exit_code;
}

}  // namespace rmhb::cli

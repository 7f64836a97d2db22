#include "rmhb/cli/commands.h"

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
#include "rmhb/cli/exit_codes.h"
#include "rmhb/plot/figures.h"
#include "rmhb/plot/plot.h"
#include "rmhb/pipeline/analyze.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
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
  ModelSettings settings = a.settings;
  settings.solve.default_tol = SolveSettings::kDefaultTolerance;  // unless --order fixes it
  const PreparedSolve prepared = Prepare(settings);
  const Model& source = prepared.model;
  if (!a.plot.empty()) plot::CheckPlotRequest(a.plot);
  AnalyzeOptions options;
  options.solve = prepared.options;
  options.identify = a.settings.solve.frequencies.empty();
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
  const int exit_code = ExitCode(s.status);
  const double total = Since(start);
  json out = s.ToJson();
  out["model"] = a.settings.model;
  out["seconds"] = total;
  if (s.solved() && !a.plot.empty()) {
    plot::PlotSolution(source, *s.solve->solution, a.plot);
    out["plot"] = a.plot;
  }
  if (a.json) {
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("analyze %s: %s\n%s", source.name.c_str(), source.equation.c_str(), s.StageReport().c_str());
    std::printf("%-10s %9.1f ms  (everything, model loading included)\n", "total", total * 1e3);
    if (s.solved())
      for (double w : s.solve->solution->frequencies()) std::printf("frequency  %.17g  (period %.17g)\n", w, 2 * M_PI / w);
  }
  if (exit_code != kExitOk && !a.json)
    std::fprintf(stderr, "rmhb: analyze: %s: %s%s\n", s.status_word().c_str(), s.message.c_str(),
                 s.solve ? (" (max|F| = " + std::to_string(s.solve->solver.final_residual) + ")").c_str() : "");
  return exit_code;
}

}  // namespace rmhb::cli

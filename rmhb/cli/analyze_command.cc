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
  app->add_option("--validate-periods", a->validate_periods,
                  "Validate over this many periods of the slowest base (default 20)")
      ->check(CLI::Range(1, 100000));
  app->add_option("--plot", a->plot,
                  "Draw two periods of the solution against CVODE started on it, their difference "
                  "and the phase portrait into FILE.png or FILE.svg (gnuplot)");
  app->add_flag("--json", a->json, "Machine-readable output");
}

int RunAnalyze(const AnalyzeArgs& a) {
  const auto start = Clock::now();
  PreparedSolve prepared = PrepareSolve(a.settings);
  const ProblemSource& source = prepared.source;
  HarmonicBalanceProblem problem = source.problem;
  const HarmonicBalanceOptions& options = prepared.options;
  const int bases = static_cast<int>(problem.frequencies.size());
  const bool identify = a.settings.frequencies.empty();
  if (!source.original && !source.original_dae)
    throw std::invalid_argument("cannot integrate the model: " + source.original_error);
  if (!std::isfinite(a.t_end) || !std::isfinite(a.transient))
    throw std::invalid_argument("--t-end and --transient must be finite numbers");
  if (!a.plot.empty()) CheckPlotRequest(a.plot);

  json out, stages = json::object();
  out["model"] = a.settings.model;
  std::string status = "converged", message;
  int exit_code = kExitOk;
  std::vector<std::string> lines;  // the text report, one per stage

  HarmonicSolution guess = prepared.guess;
  frequency_id::IdentificationSummary id;
  if (identify) {
    // 1. Trajectory of the original equations.
    // One base: enough samples that the order's highest harmonic is well
    // below Nyquist (an aliased harmonic is a line no base explains). Several:
    // the record is long (beats), and the lines above the threshold below
    // stay under 6 times the fastest base on the bundled tori; measured by
    // tests/benchmarks/frequency_id_benchmark (section 4).
    int samples_per_period = a.samples_per_period;
    if (samples_per_period == 0)
      samples_per_period = bases == 1 ? std::clamp(5 * options.order / 2, 16, 1024) : 12;
    // A periodic record's lines are exact harmonics, fitted jointly: 60
    // periods give the frequency to CVODE's drift already.
    seeding::RecordOptions record =
        seeding::DefaultRecord(problem.frequencies, samples_per_period, bases == 1 ? 60 : 200);
    // A given transient comes before the default record; a given t_end keeps
    // the default tenth as the transient.
    const double length = record.t_end - record.transient;
    if (a.t_end > 0) record.t_end = a.t_end;
    record.transient = a.transient >= 0 ? a.transient : 0.1 * record.t_end;
    if (a.t_end <= 0 && a.transient >= 0) record.t_end = a.transient + length;
    if (!(record.t_end <= 1e7)) throw std::invalid_argument("--t-end is too large (at most 1e7)");
    if (record.transient >= record.t_end) throw std::invalid_argument("--transient must be shorter than --t-end");
    record.integrator.method = source.stiff ? integrators::IntegratorOptions::Method::kBdf
                                            : integrators::IntegratorOptions::Method::kAdams;
    auto t0 = Clock::now();
    const frequency_id::Signal signal = RecordOriginal(source, problem.frequencies, source.initial_state, record);
    const double record_seconds = Since(t0);
    char text[512];
    std::snprintf(text, sizeof text, "%-10s %9.1f ms  %s rtol %.0e: %d samples, t in [%g, %g], dt %.4g",
                  "trajectory", record_seconds * 1e3,
                  OriginalIntegrator(source),
                  record.integrator.relative_tolerance, signal.num_samples(), record.transient,
                  record.t_end, record.dt);
    lines.push_back(text);
    stages["trajectory"] = {{"seconds", record_seconds}, {"samples", signal.num_samples()},
                            {"transient", record.transient}, {"t_end", record.t_end}, {"dt", record.dt},
                            {"relative_tolerance", record.integrator.relative_tolerance}};

    // 2. Identification.
    frequency_id::IdentificationOptions id_options;
    id_options.window_order = a.window;
    // CVODE's phase drift (~1e-11 relative per period at rtol 1e-13) makes
    // sidebands near 1e-9 of the strongest line over a long record: not lines
    // of the motion, and a guess needs nothing that weak (Newton adds it).
    id_options.relative_threshold = 1e-8;
    // The cost grows with the lines modelled; 32 hold every line above 1e-8
    // of the bundled examples but the asymmetric pendulum's (~60), where they
    // halve the time and keep the bases within 1e-12 (benchmark, section 4).
    id_options.max_components = 32;
    for (int b = 0; b < bases; ++b)
      if (!Unknown(problem, b)) id_options.bases.known_frequencies.push_back(problem.frequencies[b]);
    t0 = Clock::now();
    frequency_id::IdentifyFrequencies(id_options, signal, &id);
    const double id_seconds = Since(t0);
    stages["identify"] = {{"seconds", id_seconds}, {"status", ToString(id.status)}, {"message", id.message},
                          {"window_order", id.window_order}, {"lines", id.components.size()},
                          {"explained", id.num_explained}};
    std::snprintf(text, sizeof text, "%-10s %9.1f ms  %s, %zu lines (%d explained), Hann^%d, bases",
                  "identify", id_seconds * 1e3, ToString(id.status), id.components.size(),
                  id.num_explained, id.window_order);
    // The bases as selected (any basis of the lattice); the seed maps them to the model's.
    json selected = json::array();
    std::string report = text;
    for (size_t i = 0; i < id.bases.size(); ++i) {
      selected.push_back(Number(id.bases[i].frequency));
      std::snprintf(text, sizeof text, "%s b%zu = %.12g", i ? "," : "", i + 1, id.bases[i].frequency);
      report += text;
    }
    stages["identify"]["selected_bases"] = selected;
    lines.push_back(report);

    // 3. Seed.
    if (!id.IsUsable()) {
      status = "identification_failed";
      message = id.message;
      if (id.status == frequency_id::IdentificationStatus::kNoConvergence)
        message += " (a transient not yet decayed? try a longer --transient)";
      exit_code = kExitNotConverged;
    } else {
      t0 = Clock::now();
      try {
        const seeding::IdentifiedGuess seed = seeding::GuessFromIdentification(
            id, problem, MakeBasis(bases, options), source.variables, source.state_derivatives, &signal);
        const double seed_seconds = Since(t0);
        guess = seed.guess;
        for (int b = 0; b < bases; ++b) problem.frequencies[b] = seed.frequencies[b];
        json identified = json::array();
        for (int b = 0; b < bases; ++b)
          identified.push_back({{"frequency", Number(seed.frequencies[b])},
                                {"uncertainty", Number(seed.uncertainties[b])}, {"known", !Unknown(problem, b)}});
        stages["identify"]["bases"] = identified;
        stages["seed"] = {{"seconds", seed_seconds}, {"lines_used", seed.lines_used},
                          {"lines_dropped", seed.lines_dropped}, {"energy_on_basis", Number(seed.energy_on_basis)},
                          {"fitted_harmonics", seed.fitted_harmonics},
                          {"coordinates", seed.coordinates}, {"phase_shift", seed.phase_shift},
                          {"condition_residual", Number(seed.condition_residual)}};
        std::snprintf(text, sizeof text, "%-10s %9.1f ms  ", "seed", seed_seconds * 1e3);
        lines.push_back(text + seed.Report());
      } catch (const std::invalid_argument& e) {
        status = "seed_failed";
        message = e.what();
        exit_code = kExitNotConverged;
      }
    }
  }

  // 4. Solve.
  std::optional<HarmonicBalanceSummary> summary;
  if (exit_code == kExitOk) {
    summary = SolveHarmonicBalance(problem, guess, options);
    const bool converged = summary->converged();
    if (!converged) {
      status = ToString(summary->solver.status);
      message = summary->solver.message;
      exit_code = kExitNotConverged;
    } else if (!summary->physical) {
      status = "non_physical";
      message = summary->non_physical;
      exit_code = kExitNonPhysical;
    }
    const int unknowns = summary->solution ? summary->solution->num_variables() *
                                                 summary->solution->basis().num_coefficients()
                                           : 0;
    stages["solve"] = {{"seconds", summary->seconds}, {"status", converged ? "converged" : ToString(summary->solver.status)},
                       {"iterations", summary->solver.iterations}, {"residual", Number(summary->solver.final_residual)},
                       {"method", ToString(options.rule)}, {"solver", ToString(summary->solver.method)},
                       {"order", options.order}, {"harmonics", summary->solution ? summary->solution->basis().size() : 0},
                       {"coefficients", unknowns}, {"alias_free", summary->alias_free}, {"degree", summary->degree},
                       {"samples", summary->samples.size() == 1 ? json(summary->samples[0]) : json(summary->samples)}};
    char text[512];
    std::snprintf(text, sizeof text, "%-10s %9.1f ms  %s %s order %d: %s after %d iterations, max|F| %.3e",
                  "solve", summary->seconds * 1e3, bases == 1 ? "RHB" : "RMHB", ToString(options.rule),
                  options.order, converged ? "converged" : "NOT converged", summary->solver.iterations,
                  summary->solver.final_residual);
    lines.push_back(text);
    stages["solve"].update(PhysicalJson(*summary));
    if (converged) lines.push_back("physical" + std::string(17, ' ') + PhysicalLine(*summary));
    if (converged && stages.contains("identify") && stages["identify"].contains("bases")) {
      const std::vector<double>& w = summary->solution->frequencies();
      for (int b = 0; b < bases; ++b) {
        json& base = stages["identify"]["bases"][b];
        base["solved"] = Number(w[b]);
        base["difference"] = Number(w[b] - base["frequency"].get<double>());
        std::snprintf(text, sizeof text, "%-10s w%d identified %.15g +- %.1e, solved %.15g, difference %+.2e%s",
                      "", b + 1, base["frequency"].get<double>(), base["uncertainty"].get<double>(), w[b],
                      w[b] - base["frequency"].get<double>(), Unknown(problem, b) ? "" : " (known)");
        lines.push_back(text);
      }
    }
  }

  // 5. Validation against the original equations.
  if (exit_code == kExitOk) {
    const HarmonicSolution& sol = *summary->solution;
    const double slowest = *std::min_element(sol.frequencies().begin(), sol.frequencies().end());
    const double t_end = a.validate_periods * 2 * M_PI / slowest;
    const integrators::ValidationReport v = ValidateOriginal(source, sol, t_end);
    stages["validate"] = {{"seconds", v.seconds}, {"status", v.ok ? "ok" : "failed"},
                          {"max_error", Number(v.max_error)}, {"t_end", t_end},
                          {"periods", a.validate_periods}, {"integrator", v.integrator}, {"message", v.message}};
    char text[512];
    std::snprintf(text, sizeof text, "%-10s %9.1f ms  %s: max error %.3e over t in [0, %g] against %s",
                  "validate", v.seconds * 1e3, v.ok ? "ok" : "FAILED", v.max_error, t_end, v.integrator.c_str());
    lines.push_back(text + (v.message.empty() ? std::string() : " (" + v.message + ")"));
  }

  const double total = Since(start);
  out["status"] = status;
  out["message"] = message;
  out["identified"] = identify;
  out["stages"] = stages;
  out["seconds"] = total;
  if (exit_code == kExitOk) out.update(SolutionJson(*summary->solution));
  if (exit_code == kExitOk && !a.plot.empty()) {
    PlotSolution(source, *summary->solution, a.plot);
    out["plot"] = a.plot;
  }

  if (a.json) {
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("analyze %s: %s\n", source.name.c_str(), source.equation.c_str());
    for (const auto& l : lines) std::printf("%s\n", l.c_str());
    std::printf("%-10s %9.1f ms  (everything, model loading included)\n", "total", total * 1e3);
    if (exit_code == kExitOk)
      for (double w : summary->solution->frequencies())
        std::printf("frequency  %.17g  (period %.17g)\n", w, 2 * M_PI / w);
  }
  if (exit_code != kExitOk && !a.json)
    std::fprintf(stderr, "rmhb: analyze: %s: %s%s\n", status.c_str(), message.c_str(),
                 summary ? (" (max|F| = " + std::to_string(summary->solver.final_residual) + ")").c_str() : "");
  return exit_code;
}

}  // namespace rmhb::cli

#include "rmhb/cli/identify_command.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "rmhb/seeding/identified_guess.h"
#include "frequency_id/frequency_identification.h"
#include "frequency_id/signal_io.h"
#include "integrators/cvode_integrator.h"
#include "integrators/ida_integrator.h"
#include "rmhb/cli/commands.h"
#include "frequency_id/spectrum.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/cli/plot.h"
#include "rmhb/cli/problem_source.h"
#include "rmhb/cli/solve_setup.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;

// The model's own trajectory, sampled uniformly after the transient.
frequency_id::Signal Simulate(const IdentifyArgs& a, std::vector<double>* known, double* seconds,
                              std::string* integrator) {
  const ProblemSource source = LoadProblem(a.model, ParseOverrides(a.set));
  if (!source.original && !source.original_dae)
    throw std::invalid_argument("cannot integrate the model: " + source.original_error);
  const std::vector<double>& w = source.problem.frequencies;
  for (size_t b = 0; b < w.size(); ++b)
    if (source.problem.unknown_frequency.empty() || !source.problem.unknown_frequency[b]) known->push_back(w[b]);
  // 4 beats keep close bases 4 bins apart, enough for Hann^1; 20 took 14 s on
  // the asymmetric pendulum for the same bases (frequency_id_benchmark, section 4).
  seeding::RecordOptions record = seeding::DefaultRecord(w, a.samples_per_period, 300, 4);
  if (a.t_end > 0) record.t_end = a.t_end;
  record.transient = a.transient >= 0 ? a.transient : 0.1 * record.t_end;
  if (!std::isfinite(record.t_end) || record.t_end > 1e7) throw std::invalid_argument("--t-end is too large");
  if (record.transient >= record.t_end) throw std::invalid_argument("--transient must be shorter than --t-end");
  record.integrator.method = source.stiff ? integrators::IntegratorOptions::Method::kBdf
                                          : integrators::IntegratorOptions::Method::kAdams;
  // A conservative motion's torus is the one its initial state fixes.
  const Eigen::VectorXd& y0 = source.initial_state;
  const auto start = std::chrono::steady_clock::now();
  frequency_id::Signal signal = RecordOriginal(source, w, y0, record);
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  *integrator = OriginalIntegrator(source);
  return signal;
}

// --transient and --t-end cut a user's record too, measured from its first
// sample (as from t = 0 for a model's record).
void CutRecord(const IdentifyArgs& a, frequency_id::Signal* signal) {
  const long n = signal->num_samples();
  long first = 0, end = n;
  if (a.transient > 0) first = std::min(n, static_cast<long>(std::ceil(a.transient / signal->dt - 1e-9)));
  if (a.t_end > 0) end = std::min(n, static_cast<long>(std::ceil(a.t_end / signal->dt - 1e-9)));
  if (end - first < 64)
    throw std::invalid_argument("--transient/--t-end leave " + std::to_string(std::max(0L, end - first)) +
                                " of the record's " + std::to_string(n) + " samples (64 needed)");
  signal->samples = signal->samples.middleRows(first, end - first).eval();
  signal->t0 += first * signal->dt;
}

// The windowed amplitude spectrum of the first channel, and every identified
// line at its refined frequency labelled with its combination (m, n).
void PlotSpectrum(const frequency_id::Signal& signal, const frequency_id::IdentificationSummary& summary,
                  const std::string& file) {
  frequency_id::SampleGrid grid;
  grid.t0 = signal.t0;
  grid.dt = signal.dt;
  grid.size = static_cast<int>(signal.samples.rows());
  frequency_id::SpectrumAnalyzer analyzer(grid, frequency_id::Window(summary.window_order > 0 ? summary.window_order : 2));
  const Eigen::VectorXd& amplitude = analyzer.Compute(signal.samples.col(0));
  double top = 0;
  for (const auto& c : summary.components) top = std::max(top, c.frequency);
  PlotSeries spectrum{"windowed FFT, " + (summary.channel_names.empty() ? std::string("channel 1") : summary.channel_names[0]),
                      {}, {}, PlotSeries::Style::kLines, {}};
  for (int k = 1; k < analyzer.num_bins(); ++k) {
    if (analyzer.BinFrequency(k) > 1.2 * top + 1) break;
    spectrum.x.push_back(analyzer.BinFrequency(k));
    spectrum.y.push_back(amplitude(k));
  }
  PlotSeries lines{"identified lines (m, n)", {}, {}, PlotSeries::Style::kImpulses, {}};
  for (const auto& c : summary.components) {
    lines.x.push_back(c.frequency);
    lines.y.push_back(c.amplitude.size() ? c.amplitude(0) : 0.0);
    std::string label = "(";
    for (size_t i = 0; i < c.label.size(); ++i) label += (i ? "," : "") + std::to_string(c.label[i]);
    lines.labels.push_back(c.label.empty() ? "?" : label + ")");
  }
  std::string bases;
  for (const auto& b : summary.bases) {
    char w[32];
    std::snprintf(w, sizeof w, "%.10g", b.frequency);
    bases += (bases.empty() ? "" : ", ") + std::string(w);
  }
  Plot plot{"frequency identification: bases " + bases, {}};
  plot.panels.push_back({"amplitude spectrum with labelled combination tones", "angular frequency [rad/time]",
                         "amplitude", false, true, {spectrum, lines}});
  WritePlot(plot, file);
}

}  // namespace

void AddIdentifyOptions(CLI::App* app, IdentifyArgs* a) {
  app->add_option("model", a->model, "Example name or model file to integrate (or use --signal)");
  app->add_option("--signal", a->signal, "CSV file: a time column, then one column per channel");
  app->add_option("--set", a->set, "Override a model parameter: --set name=value (repeatable)");
  // Explicit values must be finite: the defaults are marked by 0 and -1.
  auto finite_at_least = [](double low, bool strict) {
    return CLI::Validator(
        [low, strict](std::string& text) -> std::string {
          char* end = nullptr;
          const double v = std::strtod(text.c_str(), &end);
          const bool ok = end != text.c_str() && *end == '\0' && std::isfinite(v) &&
                          (strict ? v > low : v >= low);
          return ok ? "" : "'" + text + "' must be a finite number " + (strict ? "> " : ">= ") + "0";
        },
        strict ? "POSITIVE" : "NONNEGATIVE");
  };
  app->add_option("--t-end", a->t_end, "Length of the integrated record (default: 300 periods of the slowest base, and at "
                  "least 20 beat periods of two close bases; with --signal: keep the first T time units)")
      ->check(finite_at_least(0, true));
  app->add_option("--transient", a->transient, "Initial time to discard (default: a tenth of --t-end; with --signal: none)")
      ->check(finite_at_least(0, false));
  app->add_option("--samples-per-period", a->samples_per_period,
                  "Samples per period of the fastest base (default 32)")
      ->check(CLI::Range(4, 4096));
  app->add_option("--window", a->window, "Hann^q window order q (0: chosen from the line spacing)")
      ->check(CLI::Range(0, 8));
  app->add_option("--plot", a->plot, "Draw the spectrum with the labelled lines into FILE.png or FILE.svg");
  app->add_flag("--json", a->json, "Machine-readable output");
  app->footer("Exit codes: 0 ok, 1 usage, 2 bad input (unreadable CSV, unknown model, bad value,\n"
              "gnuplot missing for --plot), 3 no usable bases found (the message says why), 4 internal.");
}

int RunIdentify(const IdentifyArgs& a) {
  if (a.model.empty() == a.signal.empty())
    throw std::invalid_argument("identify needs either a model or --signal FILE.csv");
  if (!a.plot.empty()) CheckPlotRequest(a.plot);
  frequency_id::Signal signal;
  std::vector<double> known;
  double integration_seconds = 0;
  std::string integrator;
  if (!a.signal.empty()) {
    const frequency_id::CsvReadResult read = frequency_id::ReadSignalCsv(a.signal, &signal);
    if (!read.ok()) throw std::invalid_argument(read.message);
    CutRecord(a, &signal);
  } else {
    signal = Simulate(a, &known, &integration_seconds, &integrator);
  }
  frequency_id::IdentificationOptions options;
  options.window_order = a.window;
  options.bases.known_frequencies = known;
  frequency_id::IdentificationSummary summary;
  frequency_id::IdentifyFrequencies(options, signal, &summary);

  json out;
  out["status"] = ToString(summary.status);
  out["message"] = summary.message;
  json bases = json::array();
  for (const auto& b : summary.bases)
    bases.push_back({{"frequency", Number(b.frequency)}, {"uncertainty", Number(b.uncertainty)}, {"known", b.known}});
  out["bases"] = bases;
  json components = json::array();
  for (const auto& c : summary.components) {
    json amp = json::array(), phase = json::array();
    for (int i = 0; i < c.amplitude.size(); ++i) amp.push_back(Number(c.amplitude(i)));
    for (int i = 0; i < c.phase.size(); ++i) phase.push_back(Number(c.phase(i)));
    components.push_back({{"frequency", Number(c.frequency)}, {"uncertainty", Number(c.frequency_uncertainty)},
                          {"label", c.label}, {"amplitude", amp}, {"phase", phase}});
  }
  out["components"] = components;
  out["channels"] = summary.channel_names;
  out["samples"] = summary.num_samples;
  out["duration"] = summary.duration;
  out["seconds"] = {{"integration", integration_seconds}, {"identification", summary.total_seconds}};
  if (!a.plot.empty()) {
    PlotSpectrum(signal, summary, a.plot);
    out["plot"] = a.plot;
  }
  if (a.json) {
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("%s\n", summary.FullReport().c_str());
    if (integration_seconds > 0)
      std::printf("trajectory: %s, %d samples over %.6g time units, %.1f ms\n", integrator.c_str(),
                  summary.num_samples, summary.duration, integration_seconds * 1e3);
  }
  return summary.IsUsable() ? kExitOk : kExitNotConverged;
}

}  // namespace rmhb::cli

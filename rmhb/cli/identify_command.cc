#include "rmhb/cli/identify_command.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "examples/identified_guess.h"
#include "frequency_id/frequency_identification.h"
#include "frequency_id/signal_io.h"
#include "integrators/cvode_integrator.h"
#include "rmhb/cli/commands.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/cli/problem_source.h"
#include "rmhb/cli/solve_setup.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;

// The model's own trajectory, sampled uniformly after the transient.
frequency_id::Signal Simulate(const IdentifyArgs& a, std::vector<double>* known, double* seconds) {
  const ProblemSource source = LoadProblem(a.model, ParseOverrides(a.set));
  if (!source.original) throw std::invalid_argument("cannot integrate the model: " + source.original_error);
  const std::vector<double>& w = source.problem.frequencies;
  for (size_t b = 0; b < w.size(); ++b)
    if (source.problem.unknown_frequency.empty() || !source.problem.unknown_frequency[b]) known->push_back(w[b]);
  // 4 beats keep close bases 4 bins apart, enough for Hann^1; 20 took 14 s on
  // the asymmetric pendulum for the same bases (frequency_id_benchmark, section 4).
  examples::RecordOptions record = examples::DefaultRecord(w, a.samples_per_period, 300, 4);
  if (a.t_end > 0) record.t_end = a.t_end;
  record.transient = a.transient >= 0 ? a.transient : 0.1 * record.t_end;
  if (!std::isfinite(record.t_end) || record.t_end > 1e7) throw std::invalid_argument("--t-end is too large");
  if (record.transient >= record.t_end) throw std::invalid_argument("--transient must be shorter than --t-end");
  record.integrator.method = source.stiff ? integrators::IntegratorOptions::Method::kBdf
                                          : integrators::IntegratorOptions::Method::kAdams;
  // A conservative motion's torus is the one its initial state fixes.
  const Eigen::VectorXd y0 = source.initial_state.size() ? source.initial_state : source.state(source.guess(5), 0.0);
  const auto start = std::chrono::steady_clock::now();
  frequency_id::Signal signal = examples::RecordTrajectory(source.original(w), y0, record, source.state_names);
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return signal;
}

}  // namespace

void AddIdentifyOptions(CLI::App* app, IdentifyArgs* a) {
  app->add_option("model", a->model, "Example name or model file to integrate (or use --signal)");
  app->add_option("--signal", a->signal, "CSV file: a time column, then one column per channel");
  app->add_option("--set", a->set, "Override a model parameter: --set name=value");
  app->add_option("--t-end", a->t_end, "Length of the integrated record (default: from the frequencies)");
  app->add_option("--transient", a->transient, "Initial time to discard (default: a tenth)");
  app->add_option("--samples-per-period", a->samples_per_period,
                  "Samples per period of the fastest base (default 32)")
      ->check(CLI::Range(4, 4096));
  app->add_option("--window", a->window, "Hann^q window order q (0: chosen from the line spacing)")
      ->check(CLI::Range(0, 8));
  app->add_flag("--json", a->json, "Machine-readable output");
}

int RunIdentify(const IdentifyArgs& a) {
  if (a.model.empty() == a.signal.empty())
    throw std::invalid_argument("identify needs either a model or --signal FILE.csv");
  frequency_id::Signal signal;
  std::vector<double> known;
  double integration_seconds = 0;
  if (!a.signal.empty()) {
    const frequency_id::CsvReadResult read = frequency_id::ReadSignalCsv(a.signal, &signal);
    if (!read.ok()) throw std::invalid_argument(read.message);
  } else {
    signal = Simulate(a, &known, &integration_seconds);
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
  if (a.json) {
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("%s\n", summary.FullReport().c_str());
    if (integration_seconds > 0)
      std::printf("trajectory: CVODE, %d samples over %.6g time units, %.1f ms\n", summary.num_samples,
                  summary.duration, integration_seconds * 1e3);
  }
  return summary.IsUsable() ? kExitOk : kExitNotConverged;
}

}  // namespace rmhb::cli

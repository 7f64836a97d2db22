#include "rmhb/pipeline/identify.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "rmhb/pipeline/report.h"
#include "rmhb/pipeline/start.h"
#include "rmhb/seeding/identified_guess.h"

namespace rmhb {
namespace {

using nlohmann::json;

// --transient and --t-end cut a user's record too, measured from its first
// sample (as from t = 0 for a model's record).
void CutRecord(const IdentifyOptions& o, frequency_id::Signal* signal) {
  const long n = signal->num_samples();
  long first = 0, end = n;
  if (o.transient > 0) first = std::min(n, static_cast<long>(std::ceil(o.transient / signal->dt - 1e-9)));
  if (o.t_end > 0) end = std::min(n, static_cast<long>(std::ceil(o.t_end / signal->dt - 1e-9)));
  if (end - first < 64)
    throw std::invalid_argument("--transient/--t-end leave " + std::to_string(std::max(0L, end - first)) +
                                " of the record's " + std::to_string(n) + " samples (64 needed)");
  signal->samples = signal->samples.middleRows(first, end - first).eval();
  signal->t0 += first * signal->dt;
}

// `options`: a user's signal's (the defaults) or a model's record's.
IdentifySummary IdentifyRecord(frequency_id::Signal signal, const std::vector<double>& known,
                               const IdentifyOptions& o, frequency_id::IdentificationOptions options) {
  IdentifySummary s;
  options.window_order = o.window;
  options.bases.known_frequencies = known;
  frequency_id::IdentifyFrequencies(options, signal, &s.identification);
  s.signal = std::move(signal);
  return s;
}

}  // namespace

std::string IdentifyOptions::IsValid() const {
  if (!std::isfinite(t_end) || t_end < 0) return "--t-end must be a finite number >= 0";
  if (!std::isfinite(transient)) return "--transient must be a finite number";
  if (samples_per_period != 0 && samples_per_period < 4) return "--samples-per-period must be 0 (automatic) or >= 4";
  if (window < 0) return "--window must be >= 0";
  return "";
}

IdentifySummary Identify(const Model& model, const IdentifyOptions& o) {
  if (const std::string error = o.IsValid(); !error.empty()) throw std::invalid_argument(error);
  if (!model.original && !model.original_dae)
    throw std::invalid_argument("cannot integrate the model: " + model.original_error);
  const std::vector<double>& w = model.problem.frequencies;
  std::vector<double> known;
  for (size_t b = 0; b < w.size(); ++b)
    if (model.problem.unknown_frequency.empty() || !model.problem.unknown_frequency[b]) known.push_back(w[b]);
  // 4 beats keep close bases 4 bins apart, enough for Hann^1; 20 took 14 s on
  // the asymmetric pendulum for the same bases (frequency_id_benchmark, section 4).
  seeding::RecordOptions record = seeding::DefaultRecord(w, o.samples_per_period > 0 ? o.samples_per_period : 32, 300, 4);
  if (o.t_end > 0) record.t_end = o.t_end;
  record.transient = o.transient >= 0 ? o.transient : 0.1 * record.t_end;
  if (!std::isfinite(record.t_end) || record.t_end > 1e7) throw std::invalid_argument("--t-end is too large");
  if (record.transient >= record.t_end) throw std::invalid_argument("--transient must be shorter than --t-end");
  record.integrator.method = model.stiff ? integrators::IntegratorOptions::Method::kBdf
                                         : integrators::IntegratorOptions::Method::kAdams;
  // A conservative motion's torus is the one its initial state fixes.
  const auto start = std::chrono::steady_clock::now();
  double perturbation = 0;
  int settle_periods = 0;
  Eigen::VectorXd y0 = model.initial_state;
  if (o.transient < 0 && known.size() == w.size()) {
    try {
      y0 = ForcedRecordStart(model, &record, &settle_periods);
    } catch (const std::runtime_error&) {
      settle_periods = 0;  // not settled within the budget: the default transient
    }
  } else {
    y0 = RecordStart(model, &perturbation);
    if (o.transient < 0) SettleAutonomousRecord(model, y0, &record, &settle_periods);
  }
  RecordSampling sampling;
  frequency_id::Signal signal = o.samples_per_period > 0 ? RecordOriginal(model, w, y0, record)
                                                         : RecordUnaliased(model, w, y0, record, &sampling);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  IdentifySummary s = IdentifyRecord(std::move(signal), known, o, RecordIdentificationOptions());
  s.rest_perturbation = perturbation;
  s.settle_periods = settle_periods;
  s.sampling = sampling;
  s.integration_seconds = seconds;
  s.integrator = OriginalIntegrator(model);
  return s;
}

IdentifySummary Identify(frequency_id::Signal signal, const IdentifyOptions& o) {
  if (const std::string error = o.IsValid(); !error.empty()) throw std::invalid_argument(error);
  CutRecord(o, &signal);
  return IdentifyRecord(std::move(signal), {}, o, frequency_id::IdentificationOptions{});
}

std::string IdentifySummary::BriefReport() const { return identification.BriefReport(); }

std::string IdentifySummary::FullReport() const {
  std::string out = identification.FullReport() + "\n";
  if (integration_seconds > 0) {
    char line[256];
    std::snprintf(line, sizeof line, "trajectory: %s, %d samples over %.6g time units, %.1f ms\n", integrator.c_str(),
                  identification.num_samples, identification.duration, integration_seconds * 1e3);
    out += line;
    if (sampling.oversampling > 1) {
      std::snprintf(line, sizeof line, "  sampled %d times as densely as 32 per period (a line would fold back), %s: %s "
                    "%.2g of the strongest line near Nyquist (level %.0e)\n", sampling.oversampling,
                    sampling.thinning == 1 ? "every sample kept" : "every 2nd sample kept",
                    sampling.resolved() ? "resolved," : "NOT RESOLVED, lines above Nyquist may fold back:",
                    sampling.top_band, kRecordLineThreshold);
      out += line;
    }
    if (settle_periods > 0) {
      std::snprintf(line, sizeof line, "  recorded once the motion settled (%d periods of the slowest base)\n",
                    settle_periods);
      out += line;
    }
    if (rest_perturbation != 0) {
      std::snprintf(line, sizeof line, "  from the initial state + %g in every state (it is an equilibrium)\n",
                    rest_perturbation);
      out += line;
    }
  }
  return out;
}

json IdentifySummary::ToJson() const {
  const frequency_id::IdentificationSummary& id = identification;
  json bases = json::array();
  for (const auto& b : id.bases)
    bases.push_back({{"frequency", JsonNumber(b.frequency)}, {"uncertainty", JsonNumber(b.uncertainty)},
                     {"drift", JsonNumber(b.drift)}, {"known", b.known}});
  json components = json::array();
  for (const auto& c : id.components) {
    json amp = json::array(), phase = json::array();
    for (int i = 0; i < c.amplitude.size(); ++i) amp.push_back(JsonNumber(c.amplitude(i)));
    for (int i = 0; i < c.phase.size(); ++i) phase.push_back(JsonNumber(c.phase(i)));
    components.push_back({{"frequency", JsonNumber(c.frequency)}, {"uncertainty", JsonNumber(c.frequency_uncertainty)},
                          {"label", c.label}, {"amplitude", amp}, {"phase", phase}});
  }
  return {{"status", ToString(id.status)},
          {"message", id.message},
          {"bases", bases},
          {"components", components},
          {"channels", id.channel_names},
          {"samples", id.num_samples},
          {"duration", id.duration},
          {"rest_perturbation", rest_perturbation},
          {"settle_periods", settle_periods},
          {"sampling", {{"oversampling", sampling.oversampling}, {"thinning", sampling.thinning},
                        {"top_band", JsonNumber(sampling.top_band)}, {"resolved", sampling.resolved()}}},
          {"seconds", {{"integration", integration_seconds}, {"identification", id.total_seconds}}}};
}

}  // namespace rmhb

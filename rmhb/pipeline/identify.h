#ifndef RMHB_PIPELINE_IDENTIFY_H_
#define RMHB_PIPELINE_IDENTIFY_H_

// The base frequencies of a motion and every spectral line labelled with its
// combination (m, n) (frequency_id/frequency_identification.h), from a
// model's own trajectory or from a sampled signal:
//   IdentifySummary s = Identify(model, IdentifyOptions{});      // integrate, then identify
//   IdentifySummary r = Identify(signal, IdentifyOptions{});     // a user's record (CSV)
// A model is integrated from its initial state (CVODE, or IDA for a DAE;
// OriginalIntegrator) and recorded after its transient; the model's known
// frequencies are given to the base selection. `rmhb identify` prints this
// summary; its JSON is ToJson(). No usable bases is a status
// (identification.status); misuse (invalid options, a model without
// original equations, a record too short once cut) throws
// std::invalid_argument; a model's record whose integration stops (a stick
// of sign() friction, a blow-up) throws std::runtime_error with where and why.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "frequency_id/frequency_identification.h"
#include "frequency_id/signal.h"
#include "rmhb/pipeline/model.h"

namespace rmhb {

struct IdentifyOptions {
  // Of the record. A model: 0 = 300 periods of the slowest base and at least
  // 4 beats of the closest pair (seeding::DefaultRecord); a signal: 0 = all
  // of it, else its first t_end time units.
  double t_end = 0;
  // Integrated (or read) but not used. -1: a tenth of t_end for a model,
  // none for a signal.
  double transient = -1;
  // Of the fastest base (a model's record). 0: 32, made denser (up to
  // kRecordOversampling times) while lines above Nyquist would fold back
  // into the record (RecordUnaliased); a given rate is taken as given.
  int samples_per_period = 0;
  int window = 0;               // Hann^q order; 0: from the line spacing
  std::string IsValid() const;  // empty when valid
};

struct IdentifySummary {
  frequency_id::IdentificationSummary identification;
  frequency_id::Signal signal;     // the record identified (after the cuts)
  double integration_seconds = 0;  // a model's record only
  std::string integrator;          // a model's record only
  double rest_perturbation = 0;    // added to an equilibrium start (RecordStart)
  // How a model's record was sampled: the asked rate, or denser
  // (samples_per_period 0); top_band 0 when not measured.
  RecordSampling sampling;
  // A forced or self-excited model's record starts once its motion settled
  // (no --transient given): the periods (returns to a section) that took, 0
  // for the default transient.
  int settle_periods = 0;

  bool usable() const { return identification.IsUsable(); }
  std::string BriefReport() const;
  // The identification's own report, and for a model's record the
  // trajectory line (integrator, samples, time).
  std::string FullReport() const;
  // `rmhb identify --json` without the plot: status, message, bases,
  // components (frequency, uncertainty, label, amplitude and phase per
  // channel), channels, samples, duration, seconds.
  nlohmann::json ToJson() const;
};

IdentifySummary Identify(const Model& model, const IdentifyOptions& options);
IdentifySummary Identify(frequency_id::Signal signal, const IdentifyOptions& options);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_IDENTIFY_H_

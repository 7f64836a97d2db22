#include "rmhb/pipeline/analyze.h"

#include "rmhb/pipeline/start.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace rmhb {
namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

bool Unknown(const HarmonicBalanceProblem& p, int b) { return !p.unknown_frequency.empty() && p.unknown_frequency[b]; }

// The record for identification. One base: enough samples that the order's
// highest harmonic is well below Nyquist (an aliased harmonic is a line no
// base explains). Several: a long record (beats), and the lines above the
// threshold stay under 6 times the fastest base on the bundled tori
// (tests/benchmarks/frequency_id_benchmark, section 4). A periodic record's
// lines are exact harmonics, fitted jointly: 60 periods give the frequency to
// CVODE's drift already.
seeding::RecordOptions Record(const Model& model, const AnalyzeOptions& o, int bases) {
  int samples_per_period = o.samples_per_period;
  if (samples_per_period == 0) samples_per_period = bases == 1 ? std::clamp(5 * o.solve.order / 2, 16, 1024) : 12;
  seeding::RecordOptions record =
      seeding::DefaultRecord(model.problem.frequencies, samples_per_period, bases == 1 ? 60 : 200);
  // A given transient comes before the default record; a given t_end keeps
  // the default tenth as the transient.
  const double length = record.t_end - record.transient;
  if (o.t_end > 0) record.t_end = o.t_end;
  record.transient = o.transient >= 0 ? o.transient : 0.1 * record.t_end;
  if (o.t_end <= 0 && o.transient >= 0) record.t_end = o.transient + length;
  // Checked up front by AnalyzeOptions::IsValid; these are the derived values.
  if (!(record.t_end <= 1e7) || record.transient >= record.t_end)
    throw std::invalid_argument("analyze: the record [" + std::to_string(record.transient) + ", " +
                                std::to_string(record.t_end) + "] is empty or too long");
  record.integrator.method = model.stiff ? integrators::IntegratorOptions::Method::kBdf
                                         : integrators::IntegratorOptions::Method::kAdams;
  return record;
}

frequency_id::IdentificationOptions IdentificationOptionsFor(const HarmonicBalanceProblem& problem, int window) {
  frequency_id::IdentificationOptions id;
  id.window_order = window;
  // CVODE's phase drift (~1e-11 relative per period at rtol 1e-13) makes
  // sidebands near 1e-9 of the strongest line over a long record: not lines
  // of the motion, and a guess needs nothing that weak (Newton adds it).
  id.relative_threshold = 1e-8;
  // The cost grows with the lines modelled; 32 hold every line above 1e-8
  // of the bundled examples but the asymmetric pendulum's (~60), where they
  // halve the time and keep the bases within 1e-12 (benchmark, section 4).
  id.max_components = 32;
  // No more bases than the model has: a line of a not quite decayed
  // transient stays unexplained instead of becoming a base of its own.
  id.bases.max_bases = static_cast<int>(problem.frequencies.size());
  for (std::size_t b = 0; b < problem.frequencies.size(); ++b)
    if (!Unknown(problem, static_cast<int>(b))) id.bases.known_frequencies.push_back(problem.frequencies[b]);
  return id;
}

// Stages 1-3: record, identify, seed. Returns the guess, or nullopt with
// the summary's status and message set.
std::optional<HarmonicSolution> IdentifyAndSeed(const Model& model, const AnalyzeOptions& o, AnalyzeSummary* s) {
  const int bases = static_cast<int>(model.problem.frequencies.size());
  // A forced periodic motion is recorded once it has settled: the transient
  // is measured (the stroboscopic map), not guessed.
  const bool settle = o.transient < 0 && bases == 1 && model.problem.num_unknown_frequencies() == 0;
  AnalyzeOptions record_options = o;
  if (settle) record_options.transient = 0;
  RecordStage stage{Record(model, record_options, bases)};
  auto t0 = Clock::now();
  Eigen::VectorXd y0 = model.initial_state;
  if (settle) {
    try {
      y0 = SettledState(model, StartOptions{}, &stage.settle_periods);
    } catch (const std::runtime_error& e) {
      s->status = AnalyzeStatus::kIdentificationFailed;
      s->message = e.what();
      return std::nullopt;
    }
  }
  const frequency_id::Signal signal = RecordOriginal(model, model.problem.frequencies, y0, stage.record);
  stage.seconds = Since(t0);
  stage.samples = signal.num_samples();
  s->trajectory = stage;

  t0 = Clock::now();
  frequency_id::IdentificationSummary id;
  frequency_id::IdentifyFrequencies(IdentificationOptionsFor(model.problem, o.window), signal, &id);
  s->identify_seconds = Since(t0);
  s->identification = id;
  if (!id.IsUsable()) {
    s->status = AnalyzeStatus::kIdentificationFailed;
    s->message = id.message;
    if (id.status == frequency_id::IdentificationStatus::kNoConvergence)
      s->message += " (a transient not yet decayed? try a longer --transient)";
    return std::nullopt;
  }
  t0 = Clock::now();
  try {
    s->seed = seeding::GuessFromIdentification(id, model.problem, MakeBasis(bases, o.solve), model.variables,
                                               model.state_derivatives, &signal);
  } catch (const std::invalid_argument& e) {
    s->status = AnalyzeStatus::kSeedFailed;
    s->message = e.what();
    return std::nullopt;
  }
  s->seed_seconds = Since(t0);
  for (int b = 0; b < bases; ++b) s->problem.frequencies[b] = s->seed->frequencies[b];
  return s->seed->guess;
}

}  // namespace

const char* ToString(AnalyzeStatus status) {
  switch (status) {
    case AnalyzeStatus::kConverged: return "converged";
    case AnalyzeStatus::kIdentificationFailed: return "identification_failed";
    case AnalyzeStatus::kSeedFailed: return "seed_failed";
    case AnalyzeStatus::kNotConverged: return "not_converged";
    case AnalyzeStatus::kNonPhysical: return "non_physical";
    case AnalyzeStatus::kValidationExceeded: return "validation_exceeded";
  }
  return "not_converged";
}

std::string AnalyzeOptions::IsValid() const {
  if (!std::isfinite(t_end) || !std::isfinite(transient)) return "t_end and transient must be finite numbers";
  if (t_end < 0) return "t_end must be >= 0";
  if (t_end > 1e7 || transient > 1e7) return "t_end is too large (at most 1e7)";
  if (t_end > 0 && transient >= t_end) return "the transient must be shorter than t_end";
  if (samples_per_period < 0) return "samples_per_period must be >= 0";
  if (window < 0) return "window must be >= 0";
  if (validate_periods < 1) return "validate_periods must be >= 1";
  if (!(validate_tolerance > 0)) return "validate_tolerance must be > 0";
  return solve.IsValid();
}

AnalyzeSummary Analyze(const Model& model, const AnalyzeOptions& options) {
  const auto start = Clock::now();
  if (const std::string error = options.IsValid(); !error.empty()) throw std::invalid_argument("analyze: " + error);
  if (!model.original && !model.original_dae)
    throw std::invalid_argument("cannot integrate the model: " + model.original_error);
  AnalyzeSummary s;
  s.problem = model.problem;
  s.identified = options.identify;
  std::optional<HarmonicSolution> guess;
  if (options.identify)
    guess = IdentifyAndSeed(model, options, &s);
  else
    guess = GuessAtOrder(model, options.solve.order);
  if (guess) {
    s.solve = SolveHarmonicBalance(s.problem, *guess, options.solve);
    if (!s.solve->converged()) {
      s.status = AnalyzeStatus::kNotConverged;
      s.message = s.solve->solver.message;
    } else if (!s.solve->physical) {
      s.status = AnalyzeStatus::kNonPhysical;
      s.message = s.solve->non_physical;
    } else {
      s.status = AnalyzeStatus::kConverged;
      const HarmonicSolution& sol = *s.solve->solution;
      const double slowest = *std::min_element(sol.frequencies().begin(), sol.frequencies().end());
      s.validation_t_end = options.validate_periods * 2 * M_PI / slowest;
      s.validation = ValidateOriginal(model, sol, s.validation_t_end);
      s.verdict = JudgeValidation(model, sol, *s.validation, s.validation_t_end, options.validate_tolerance);
      if (!s.verdict->ok) {
        s.status = AnalyzeStatus::kValidationExceeded;
        s.message = "validation " + s.verdict->Describe();
      }
    }
  }
  s.seconds = Since(start);
  return s;
}

std::string AnalyzeSummary::BriefReport() const {
  std::ostringstream out;
  out << "analyze: " << ToString(status);
  if (solve && solve->solution) {
    out << ", frequencies";
    for (double w : solve->solution->frequencies()) out << " " << w;
  }
  if (validation) out << ", validation max error " << validation->max_error;
  if (!message.empty()) out << " (" << message << ")";
  out << ", " << seconds << " s\n";
  return out.str();
}

std::string AnalyzeSummary::FullReport() const {
  std::ostringstream out;
  if (trajectory)
    out << "trajectory  " << trajectory->samples << " samples, t in [" << trajectory->record.transient << ", "
        << trajectory->record.t_end << "], " << trajectory->seconds << " s\n";
  if (identification)
    out << "identify    " << frequency_id::ToString(identification->status) << ", "
        << identification->components.size() << " lines, " << identify_seconds << " s\n";
  if (seed) out << "seed        " << seed->Report() << "\n";
  if (solve) out << "solve       " << solve->BriefReport() << "\n";
  if (validation)
    out << "validate    max error " << validation->max_error << " over [0, " << validation_t_end << "] against "
        << validation->integrator << (verdict ? ", " + verdict->Describe() : std::string()) << "\n";
  return out.str() + BriefReport();
}

}  // namespace rmhb

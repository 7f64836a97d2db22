#include "rmhb/pipeline/analyze.h"


#include "rmhb/pipeline/report.h"
#include "rmhb/pipeline/start.h"
#include "rmhb/pipeline/torus.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "integrators/cvode_integrator.h"

namespace rmhb {
namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

bool Unknown(const HarmonicBalanceProblem& p, int b) { return !p.unknown_frequency.empty() && p.unknown_frequency[b]; }

// The record's integrator: the model's choice, or BDF when Adams cannot
// cover one slowest period from initial_state in twice the steps BDF takes
// (rtol 1e-10). Van der Pol at mu = 20 (a user's file) takes 5.7x more Adams
// steps (its record: 2.2 s against 0.4 s); at mu = 5, the pendulum, Kepler's
// orbit and the Brusselator 0.3-0.7x. Validation keeps the model's choice:
// BDF at its tolerance is not accurate enough for 1e-8 there.
integrators::IntegratorOptions::Method RecordMethod(const Model& model) {
  using Method = integrators::IntegratorOptions::Method;
  if (model.stiff) return Method::kBdf;
  if (!model.original || model.initial_state.size() == 0) return Method::kAdams;
  const double slowest = *std::min_element(model.problem.frequencies.begin(), model.problem.frequencies.end());
  if (!(slowest > 0)) return Method::kAdams;
  const integrators::OdeSystem ode = model.original(model.problem.frequencies);
  integrators::IntegratorOptions io;
  io.relative_tolerance = 1e-10;
  io.absolute_tolerance = 1e-12;
  io.method = Method::kBdf;
  const integrators::IntegrationResult bdf = integrators::IntegrateOde(ode, model.initial_state, 0, {2 * M_PI / slowest}, io);
  if (!bdf.ok()) return Method::kAdams;
  io.method = Method::kAdams;
  io.max_steps = 2 * std::max(bdf.steps, 50L);
  const bool adams = integrators::IntegrateOde(ode, model.initial_state, 0, {2 * M_PI / slowest}, io).ok();
  return adams ? Method::kAdams : Method::kBdf;
}

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
  record.integrator.method = RecordMethod(model);
  return record;
}

// One period sampled this often resolves harmonics up to 2047; a seed needs
// no more than kMaxPeriodOrder of them (order selection goes on from there).
constexpr int kPeriodSamples = 4096;
constexpr double kSeedSymmetryTolerance = 1e-9;
constexpr int kMaxPeriodOrder = 1024;

frequency_id::IdentificationOptions IdentificationOptionsFor(const HarmonicBalanceProblem& problem, int window) {
  frequency_id::IdentificationOptions id = RecordIdentificationOptions();
  id.window_order = window;
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

// An autonomous orbit (one unknown base, ODE): one exact period from the
// record's last (settled) state, 4096 samples (rmhb/METHOD.md s.20). The
// record's fit stops at 0.8 of its Nyquist (~25 harmonics at its ~60
// samples per period), a relaxation oscillation needs hundreds (Van der Pol
// at eps = 5: 312 for 1e-10).
// `frequency` is the identified one, or the problem's guess when the
// identification failed (below).
std::optional<frequency_id::Signal> OrbitPeriod(const Model& model, const frequency_id::Signal& record,
                                                double frequency, integrators::IntegratorOptions::Method method) {
  if (model.problem.frequencies.size() != 1 || !Unknown(model.problem, 0) || !model.original || !(frequency > 0))
    return std::nullopt;
  integrators::IntegratorOptions io;
  io.method = method;  // the record's
  io.relative_tolerance = 1e-12;
  io.absolute_tolerance = 1e-14;
  const Eigen::VectorXd y0 = record.samples.bottomRows(1).transpose();
  const double t0 = record.t0 + (record.num_samples() - 1) * record.dt;
  return seeding::OnePeriod(model.original(model.problem.frequencies), y0, t0, 2 * M_PI / frequency,
                            kPeriodSamples, io);
}

// With a target, the order is where order selection starts: where the
// period's harmonics fall below 1e-9 of the largest when that is higher
// (a default target's cap, 4x the start, follows it).
void StartAtPeriodOrder(const frequency_id::Signal& period, HarmonicBalanceOptions* options) {
  const int order = std::min(seeding::PeriodOrder(period, 1e-9), kMaxPeriodOrder);
  if (order <= options->order) return;
  if (options->soft_tolerance) options->max_order = std::max(options->max_order, 4 * order);
  options->order = order;
}

// Stages 1-3: record, identify, seed. Returns the guess, or nullopt with
// the summary's status and message set.
std::optional<HarmonicSolution> IdentifyAndSeed(const Model& model, const AnalyzeOptions& o, AnalyzeSummary* s) {
  const int bases = static_cast<int>(model.problem.frequencies.size());
  RecordStage stage;
  stage.record = Record(model, o, bases);
  stage.integrator = OriginalIntegrator(model, stage.record.integrator.method);
  auto t0 = Clock::now();
  Eigen::VectorXd y0;
  if (o.transient < 0 && model.problem.num_unknown_frequencies() == 0) {
    // The transient of a forced motion is measured, not guessed.
    try {
      y0 = ForcedRecordStart(model, &stage.record, &stage.settle_periods);
    } catch (const std::runtime_error& e) {
      s->status = AnalyzeStatus::kIdentificationFailed;
      s->message = e.what();
      return std::nullopt;
    }
  } else {
    y0 = RecordStart(model, &stage.rest_perturbation);
    // So is a self-excited one's.
    if (o.transient < 0) SettleAutonomousRecord(model, y0, &stage.record, &stage.settle_periods);
  }
  // A torus' record keeps its rate: its identification keeps the 32
  // strongest lines, far above what folds back from beyond 6 times the
  // fastest base on the bundled tori, and a second integration doubled the
  // stage for nothing (asymmetric pendulum: 1.3 s -> 2.3 s, the same bases).
  const frequency_id::Signal signal =
      o.samples_per_period > 0 || bases > 1
          ? RecordOriginal(model, model.problem.frequencies, y0, stage.record)
          : RecordUnaliased(model, model.problem.frequencies, y0, stage.record, &stage.sampling);
  stage.seconds = Since(t0);
  stage.samples = signal.num_samples();
  s->trajectory = stage;

  t0 = Clock::now();
  frequency_id::IdentificationSummary id;
  frequency_id::IdentifyFrequencies(IdentificationOptionsFor(model.problem, o.window), signal, &id);
  s->identify_seconds = Since(t0);
  s->identification = id;
  t0 = Clock::now();
  const bool one_base = id.bases.size() == 1;
  const std::optional<frequency_id::Signal> period =
      OrbitPeriod(model, signal, id.IsUsable() ? (one_base ? id.bases[0].frequency : 0) : model.problem.frequencies[0],
                  stage.record.integrator.method);
  // One exact period seeds an autonomous orbit by itself: the identification
  // only had to find its length roughly, and the problem's guess (the
  // trajectory's own period for a file without frequencies) serves when it
  // failed (Van der Pol at mu = 5 from its exact period: the polishing of a
  // relaxation cycle's many lines stopped; rmhb/METHOD.md s.20).
  if (!id.IsUsable() && !period) {
    s->status = AnalyzeStatus::kIdentificationFailed;
    s->message = id.message;
    if (id.status == frequency_id::IdentificationStatus::kNoConvergence)
      s->message += " (a transient not yet decayed? try analyze with a longer --transient)";
    return std::nullopt;
  }
  if (period && s->solve_options.tolerance > 0) StartAtPeriodOrder(*period, &s->solve_options);
  try {
    const HarmonicBasis basis = MakeBasis(bases, s->solve_options);
    s->seed = id.IsUsable() ? seeding::GuessFromIdentification(id, model.problem, basis, model.variables,
                                                               model.state_derivatives, &signal,
                                                               period ? &*period : nullptr)
                            : seeding::GuessFromPeriod(model.problem, basis, model.variables,
                                                       model.state_derivatives, *period);
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
  if (locking_transient < 0 || max_locking_denominator < 1 || !(locking_tolerance > 0))
    return "locking_transient must be >= 0, max_locking_denominator >= 1, locking_tolerance > 0";
  return solve.IsValid();
}

namespace {

// The locked orbit of a forced torus whose motion repeats every q forcing
// periods: the model on the base w1/q (LockedModel; p does not enter a
// forced model's equations, LockedResonance reads it off the solution).
AnalyzeSummary AnalyzeLocked(const Model& model, const AnalyzeOptions& options, int q, double mismatch) {
  AnalyzeOptions o = options;
  o.solve.order = options.solve.order * q;
  o.solve.basis_for_order = nullptr;
  o.solve.shape = BasisShape::kDiamond;
  o.solve.samples.clear();
  AnalyzeSummary s = Analyze(LockedModel(model, {1, q, 0}), o);
  char text[300];
  if (s.solve && s.solve->solution) {
    const Resonance lock = LockedResonance(*s.solve->solution, q);
    std::snprintf(text, sizeof text,
                  "locked %d:%d (w2/w1 = %d/%d): periodic with base w1/%d = %.15g; the state at multiples of the "
                  "forcing period repeats every %d periods to %.1e",
                  lock.p, q, lock.p, q, q, s.solve->solution->frequencies()[0], q, mismatch);
  } else {
    std::snprintf(text, sizeof text, "locked (the state repeats every %d forcing periods to %.1e)", q, mismatch);
  }
  s.motion = text;
  return s;
}

// An autonomous torus model (both frequencies unknown) whose motion is
// locked: one unknown base explains it. The model on one base (LockedModel
// at 1:1; an autonomous model's equations do not contain its frequencies,
// p/q only maps a torus' harmonics) is analyzed after locking_transient
// periods of its slowest guess; a converged orbit that CVODE validates, that
// carries the record's line energy on its one base and has the identified
// frequency is the motion. Else nullopt, with why in *motion.
std::optional<AnalyzeSummary> AnalyzeAutonomousLocked(const Model& model, const AnalyzeOptions& options,
                                                     std::string* motion) {
  AnalyzeOptions o = options;
  const std::vector<double>& w = model.problem.frequencies;
  if (o.transient < 0) o.transient = options.locking_transient * 2 * M_PI / *std::min_element(w.begin(), w.end());
  o.detect_locking = false;
  o.solve.basis_for_order = nullptr;
  o.solve.shape = BasisShape::kDiamond;
  o.solve.samples.clear();
  AnalyzeSummary s = Analyze(LockedModel(model, {1, 1, 0}), o);
  char text[300];
  // A converged, validated orbit need not be the recorded motion (an
  // unstable periodic orbit validates over a few periods): the one base must
  // carry the record's line energy, and the orbit must have its frequency.
  constexpr double kLockedEnergy = 0.999, kLockedFrequency = 1e-6;
  const bool explained = s.seed && s.seed->energy_on_basis >= kLockedEnergy;
  const bool same = s.ok() && explained &&
                    std::abs(s.solve->solution->frequencies()[0] - s.seed->frequencies[0]) <=
                        kLockedFrequency * s.seed->frequencies[0];
  if (same) {
    std::snprintf(text, sizeof text,
                  "locked: one base frequency, %.15g, explains the motion after a transient of %g (validated: %s)",
                  s.solve->solution->frequencies()[0], o.transient, s.verdict->Describe().c_str());
    s.motion = text;
    return s;
  }
  if (s.ok() && !explained)
    std::snprintf(text, sizeof text,
                  "quasi-periodic: one base frequency carries %.1f%% of the line energy (< %.1f%%)",
                  100 * s.seed->energy_on_basis, 100 * kLockedEnergy);
  else if (s.ok())
    std::snprintf(text, sizeof text,
                  "quasi-periodic: the one-base orbit (w = %.12g) is not the motion's (identified %.12g)",
                  s.solve->solution->frequencies()[0], s.seed->frequencies[0]);
  else
    std::snprintf(text, sizeof text, "quasi-periodic: one base frequency does not explain the motion (%s: %s)",
                  ToString(s.status), s.message.substr(0, 120).c_str());
  *motion = text;
  return std::nullopt;
}

// The imposable symmetries a recorded motion's spectrum has to
// kSeedSymmetryTolerance of its largest coefficient, added to *problem: what
// is left of the other parity is the transient and the record's own error
// (1e-12 of the largest coefficient for the settled forced pendulum and
// quintic oscillator), and Newton from the seed projected on the subspace
// reaches the symmetric solution exactly (the forced pendulum from rest: 77
// unknowns instead of 153 at N = 25). A symmetry-broken motion would have to
// be within 1e-9 of symmetric to be held to the symmetric orbit next to it.
std::vector<HalfTurnSymmetry> SeededSymmetries(const HarmonicSolution& seed, HarmonicBalanceProblem* problem) {
  const std::vector<HalfTurnSymmetry> held =
      SymmetriesOf(seed, ImposableSymmetries(*problem), problem->symmetries, kSeedSymmetryTolerance);
  problem->symmetries.insert(problem->symmetries.end(), held.begin(), held.end());
  return held;
}

}  // namespace

AnalyzeSummary Analyze(const Model& model, const AnalyzeOptions& options) {
  const auto start = Clock::now();
  if (const std::string error = options.IsValid(); !error.empty()) throw std::invalid_argument("analyze: " + error);
  if (!model.original && !model.original_dae)
    throw std::invalid_argument("cannot integrate the model: " + model.original_error);
  std::string motion;
  if (options.identify && options.detect_locking && IsForcedTorus(model) && model.initial_state.size() > 0) {
    double mismatch = 0;
    const int q = LockedPeriods(model, options.locking_transient, options.max_locking_denominator,
                                options.locking_tolerance, &mismatch);
    if (q > 0) return AnalyzeLocked(model, options, q, mismatch);
    char text[200];
    std::snprintf(text, sizeof text,
                  "quasi-periodic: the state at multiples of the forcing period repeats for no q <= %d (closest "
                  "%.1e > %.0e)",
                  options.max_locking_denominator, mismatch, options.locking_tolerance);
    motion = text;
  }
  if (options.identify && options.detect_locking && IsAutonomousTorus(model) && model.initial_state.size() > 0)
    if (std::optional<AnalyzeSummary> locked = AnalyzeAutonomousLocked(model, options, &motion)) return *locked;
  AnalyzeSummary s;
  s.motion = motion;
  s.default_conditions = model.DefaultConditions();
  s.conditions_note = model.conditions_note;
  s.problem = model.problem;
  s.solve_options = options.solve;
  s.validate_periods = options.validate_periods;
  s.identified = options.identify;
  std::optional<HarmonicSolution> guess;
  if (options.identify)
    guess = IdentifyAndSeed(model, options, &s);
  else
    guess = GuessAtOrder(model, options.solve.order);
  if (guess) {
    // A forced periodic record spans whole periods: its spectrum has no
    // leakage, unlike an identified one, whose lines stop at a threshold.
    const bool recorded = options.identify && s.problem.frequencies.size() == 1 && s.problem.num_unknown_frequencies() == 0;
    const std::vector<HalfTurnSymmetry> seeded = recorded ? SeededSymmetries(*guess, &s.problem) : std::vector<HalfTurnSymmetry>{};
    s.solve = SolveHarmonicBalance(s.problem, *guess, s.solve_options);
    s.solve->symmetries_found.insert(s.solve->symmetries_found.begin(), seeded.begin(), seeded.end());
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

namespace {

using nlohmann::json;

// The stages as JSON and as text lines, built together so they agree.
struct Stages {
  json stages = json::object();
  std::vector<std::string> lines;
};

void ReportIdentification(const AnalyzeSummary& s, Stages* out) {
  const seeding::RecordOptions& record = s.trajectory->record;
  const RecordSampling& sampling = s.trajectory->sampling;
  const double dt = record.dt / sampling.oversampling * sampling.thinning;  // the record's own
  out->lines.push_back(
      StringPrintf("%-10s %9.1f ms  %s rtol %.0e: %d samples, t in [%g, %g], dt %.4g", "trajectory",
             s.trajectory->seconds * 1e3, s.trajectory->integrator.c_str(), record.integrator.relative_tolerance,
             s.trajectory->samples, record.transient, record.t_end, dt) +
      (sampling.oversampling > 1 && sampling.thinning < sampling.oversampling
           ? StringPrintf(" (%dx the rate asked: a line would fold back)", sampling.oversampling / sampling.thinning)
           : std::string()) +
      (sampling.resolved() ? std::string()
                           : StringPrintf(" (NOT resolved: %.2g of the strongest line near Nyquist > %.0e)", sampling.top_band,
                                          kRecordLineThreshold)) +
      (s.trajectory->settle_periods > 0
           ? " after the motion settled (" + std::to_string(s.trajectory->settle_periods) + " periods)"
           : std::string()) +
      (s.trajectory->rest_perturbation != 0
           ? StringPrintf(" from the start + %g in every state (the start is an equilibrium)",
                          s.trajectory->rest_perturbation)
           : std::string()));
  out->stages["trajectory"] = {{"seconds", s.trajectory->seconds}, {"samples", s.trajectory->samples},
                               {"transient", record.transient}, {"t_end", record.t_end}, {"dt", dt},
                               {"sampling", {{"oversampling", sampling.oversampling}, {"thinning", sampling.thinning},
                                             {"top_band", JsonNumber(sampling.top_band)}, {"resolved", sampling.resolved()}}},
                               {"relative_tolerance", record.integrator.relative_tolerance},
                               {"settle_periods", s.trajectory->settle_periods},
                               {"rest_perturbation", s.trajectory->rest_perturbation}};
  if (!s.identification) return;
  const frequency_id::IdentificationSummary& id = *s.identification;
  json& identify = out->stages["identify"];
  identify = {{"seconds", s.identify_seconds}, {"status", ToString(id.status)}, {"message", id.message},
              {"window_order", id.window_order}, {"lines", id.components.size()}, {"explained", id.num_explained}};
  std::string report = StringPrintf("%-10s %9.1f ms  %s, %zu lines (%d explained), Hann^%d, bases", "identify",
                              s.identify_seconds * 1e3, ToString(id.status), id.components.size(), id.num_explained,
                              id.window_order);
  // The bases as selected (any basis of the lattice); the seed maps them to the model's.
  json selected = json::array();
  for (size_t i = 0; i < id.bases.size(); ++i) {
    selected.push_back(JsonNumber(id.bases[i].frequency));
    report += StringPrintf("%s b%zu = %.12g", i ? "," : "", i + 1, id.bases[i].frequency);
  }
  identify["selected_bases"] = selected;
  out->lines.push_back(report);
  if (!s.seed) return;
  const seeding::IdentifiedGuess& seed = *s.seed;
  json identified = json::array();
  for (size_t b = 0; b < seed.frequencies.size(); ++b)
    identified.push_back({{"frequency", JsonNumber(seed.frequencies[b])},
                          {"uncertainty", JsonNumber(seed.uncertainties[b])},
                          {"known", !Unknown(s.problem, static_cast<int>(b))}});
  identify["bases"] = identified;
  out->stages["seed"] = {{"seconds", s.seed_seconds}, {"lines_used", seed.lines_used},
                         {"lines_dropped", seed.lines_dropped}, {"energy_on_basis", JsonNumber(seed.energy_on_basis)},
                         {"fitted_harmonics", seed.fitted_harmonics}, {"period_harmonics", seed.period_harmonics}, {"coordinates", seed.coordinates},
                         {"phase_shift", seed.phase_shift}, {"condition_residual", JsonNumber(seed.condition_residual)}};
  out->lines.push_back(StringPrintf("%-10s %9.1f ms  ", "seed", s.seed_seconds * 1e3) + seed.Report());
}

void ReportSolve(const AnalyzeSummary& s, Stages* out) {
  const HarmonicBalanceSummary& summary = *s.solve;
  const HarmonicBalanceOptions& options = s.solve_options;
  const bool converged = summary.converged();
  const int bases = static_cast<int>(s.problem.frequencies.size());
  const int unknowns =
      summary.solution ? summary.solution->num_variables() * summary.solution->basis().num_coefficients() : 0;
  const int order = summary.order > 0 ? summary.order : options.order;  // where order selection ended
  json& solve = out->stages["solve"];
  solve = {{"seconds", summary.seconds}, {"status", converged ? "converged" : ToString(summary.solver.status)},
           {"iterations", summary.solver.iterations}, {"residual", JsonNumber(summary.solver.final_residual)},
           {"method", ToString(options.rule)}, {"solver", ToString(summary.solver.method)},
           {"order", order}, {"harmonics", summary.solution ? summary.solution->basis().size() : 0},
           {"coefficients", unknowns}, {"alias_free", summary.alias_free}, {"degree", summary.degree},
           {"samples", summary.samples.size() == 1 ? json(summary.samples[0]) : json(summary.samples)}};
  out->lines.push_back(StringPrintf("%-10s %9.1f ms  %s %s order %d: %s after %d iterations, max|F| %.3e", "solve",
                              summary.seconds * 1e3, bases == 1 ? "RHB" : "RMHB", ToString(options.rule),
                              order, converged ? "converged" : "NOT converged", summary.solver.iterations,
                              summary.solver.final_residual));
  solve.update(PhysicalJson(summary));
  if (converged) out->lines.push_back("physical" + std::string(17, ' ') + PhysicalLine(summary));
  if (!converged || !out->stages.contains("identify") || !out->stages["identify"].contains("bases")) return;
  const std::vector<double>& w = summary.solution->frequencies();
  for (int b = 0; b < bases; ++b) {
    json& base = out->stages["identify"]["bases"][b];
    base["solved"] = JsonNumber(w[b]);
    base["difference"] = JsonNumber(w[b] - base["frequency"].get<double>());
    out->lines.push_back(StringPrintf("%-10s w%d identified %.15g +- %.1e, solved %.15g, difference %+.2e%s", "", b + 1,
                                base["frequency"].get<double>(), base["uncertainty"].get<double>(), w[b],
                                w[b] - base["frequency"].get<double>(), Unknown(s.problem, b) ? "" : " (known)"));
  }
}

void ReportValidation(const AnalyzeSummary& s, Stages* out) {
  const integrators::ValidationReport& v = *s.validation;
  const bool within = s.verdict && s.verdict->ok;
  out->stages["validate"] = {{"seconds", v.seconds}, {"status", !v.ok ? "failed" : within ? "ok" : "exceeds"},
                             {"max_error", JsonNumber(v.max_error)}, {"t_end", s.validation_t_end},
                             {"relative_error", JsonNumber(s.verdict ? s.verdict->relative_error : NAN)},
                             {"tolerance", s.verdict ? s.verdict->tolerance : NAN},
                             {"periods", s.validate_periods}, {"integrator", v.integrator}, {"message", v.message}};
  out->lines.push_back(
      StringPrintf("%-10s %9.1f ms  %s: max error %.3e (relative %.2e, tolerance %.0e) over t in [0, %g] against %s",
             "validate", v.seconds * 1e3, !v.ok ? "FAILED" : within ? "ok" : "EXCEEDS", v.max_error,
             s.verdict ? s.verdict->relative_error : NAN, s.verdict ? s.verdict->tolerance : NAN, s.validation_t_end,
             v.integrator.c_str()) +
      (v.message.empty() ? std::string() : " (" + v.message + ")"));
}

Stages Report(const AnalyzeSummary& s) {
  Stages out;
  if (s.trajectory) ReportIdentification(s, &out);
  if (s.solve) ReportSolve(s, &out);
  if (s.validation) ReportValidation(s, &out);
  return out;
}

}  // namespace

std::string AnalyzeSummary::status_word() const {
  return status == AnalyzeStatus::kNotConverged && solve ? ToString(solve->solver.status) : ToString(status);
}

std::string AnalyzeSummary::StageReport() const {
  std::string out = motion.empty() ? "" : "motion     " + motion + "\n";
  if (!default_conditions.empty())
    out += "conditions " + DefaultConditionsText(default_conditions, conditions_note) + "\n";
  for (const std::string& line : Report(*this).lines) out += line + "\n";
  return out;
}

std::string AnalyzeSummary::FullReport() const { return StageReport() + BriefReport(); }

json AnalyzeSummary::ToJson() const {
  json out = {{"status", status_word()}, {"message", message}, {"identified", identified},
              {"stages", Report(*this).stages}};
  if (!motion.empty()) out["motion"] = motion;
  if (!default_conditions.empty())
    out["default_conditions"] = DefaultConditionsJson(default_conditions, conditions_note);
  if (solved()) out.update(SolutionJson(*solve->solution));
  return out;
}

}  // namespace rmhb

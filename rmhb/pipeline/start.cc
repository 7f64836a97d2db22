#include "rmhb/pipeline/start.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>

#include "integrators/cvode_integrator.h"
#include "integrators/event_detection.h"
#include "rmhb/pipeline/analyze.h"

namespace rmhb {
namespace {

// An estimated error above this is no orbit to keep when another start exists.
constexpr double kFarFromTarget = 1e-3;

bool Unknown(const HarmonicBalanceProblem& p) { return p.num_unknown_frequencies() > 0; }

// Analyze with a record that starts on the settled state (identification
// of known frequencies: the harmonics are fitted on the record).
std::optional<HarmonicBalanceSummary> SolveFromRecord(const Model& model, const Eigen::VectorXd& y0,
                                                      const HarmonicBalanceOptions& options, std::string* why) {
  Model settled = model;
  settled.initial_state = y0;
  AnalyzeOptions analyze;
  analyze.solve = options;
  analyze.transient = 0;
  analyze.validate_periods = 1;
  const AnalyzeSummary a = Analyze(settled, analyze);
  if (a.solve && a.solve->usable()) return a.solve;
  *why = std::string(ToString(a.status)) + (a.message.empty() ? "" : ": " + a.message);
  return std::nullopt;
}

// A solution that does not move: every harmonic but the mean (coefficient
// 0, HarmonicBasis) below 1e-12 of max(1, the largest mean). Read off the
// coefficients, not sampled: it runs after every forced solve.
bool ConstantInTime(const HarmonicSolution& x) {
  const Eigen::MatrixXd& c = x.coefficients();
  if (c.cols() < 2) return true;
  const double size = std::max(1.0, c.col(0).cwiseAbs().maxCoeff());
  return c.rightCols(c.cols() - 1).cwiseAbs().maxCoeff() <= 1e-12 * size;
}

// A forced model whose guess (rest, for a file without one) converged to a
// solution constant in time: rest is a solution only where the forcing is
// parametric (x'' + c x' + (1 + h cos 2t) x + x^3 = 0), and there it may be
// unstable while the motion settles on an orbit that moves. That orbit,
// from the model's start (moved off rest as RecordStart does), replaces
// the constant one; a motion that settles to rest keeps it (nullopt).
std::optional<StartedSolve> MovingAttractor(const Model& model, const HarmonicBalanceOptions& options,
                                            const StartOptions& start, StartedSolve* constant) {
  Model moved = model;
  double perturbation = 0;
  moved.initial_state = RecordStart(model, &perturbation);
  std::string why;
  try {
    int periods = 0;
    const Eigen::VectorXd y = SettledState(moved, start, &periods);
    std::optional<HarmonicBalanceSummary> solved = SolveFromRecord(model, y, options, &why);
    if (solved && !ConstantInTime(*solved->solution)) {
      const std::string note = "from the guess: a solution constant in time; the motion from the start" +
                               std::string(perturbation != 0 ? " (+ 0.1, rest is an equilibrium)" : "") +
                               " settles on one that moves";
      return StartedSolve{*solved, "simulation (" + std::to_string(periods) + " periods to settle)", note, periods};
    }
    if (!solved) constant->note = "the guess's solution is constant in time; from the simulated start: " + why;
  } catch (const std::runtime_error& e) {
    constant->note = "the guess's solution is constant in time; simulated start: " + std::string(e.what());
  }
  return std::nullopt;
}

}  // namespace

std::string WhyNotKept(const HarmonicBalanceSummary& s) {
  if (!s.converged()) {
    char residual[48];  // %g: a model in SI units has residuals of 1e-7 (std::to_string printed 0.000000)
    std::snprintf(residual, sizeof residual, ", max|F| %.3g", s.solver.final_residual);
    return std::string(ToString(s.solver.status)) + residual;
  }
  if (!s.physical) return "non-physical: " + s.non_physical;
  char far[96];
  std::snprintf(far, sizeof far, "order %d, estimated error %.2g (> %.0e: not yet the orbit)", s.order,
                s.truncation_estimate, kFarFromTarget);
  return far;
}

std::string StartOptions::IsValid() const {
  if (!(settle_tolerance > 0)) return "settle_tolerance must be > 0";
  if (max_periods < 2) return "max_periods must be >= 2";
  if (!(max_seconds > 0)) return "max_seconds must be > 0";
  return "";
}

namespace {

// How a start is integrated until it settles (SettledState, TorusSettleTime).
integrators::IntegratorOptions SettleIntegration(const Model& model) {
  integrators::IntegratorOptions io;
  io.method = model.stiff ? integrators::IntegratorOptions::Method::kBdf : integrators::IntegratorOptions::Method::kAdams;
  io.relative_tolerance = 1e-11;
  io.absolute_tolerance = 1e-13;
  return io;
}

}  // namespace

Eigen::VectorXd SettledState(const Model& model, const StartOptions& start, int* periods) {
  const double T = 2 * M_PI / model.problem.frequencies[0];
  const integrators::IntegratorOptions io = SettleIntegration(model);
  const auto begin = std::chrono::steady_clock::now();
  Eigen::VectorXd y = model.initial_state;
  constexpr int kChunk = 25;  // periods per integration call
  for (int done = 0; done < start.max_periods; done += kChunk) {
    std::vector<double> times;
    for (int k = 0; k <= kChunk; ++k) times.push_back(k * T);
    const integrators::IntegrationResult r = SimulateOriginal(model, model.problem.frequencies, y, times, io);
    if (!r.ok()) throw std::runtime_error("the simulated start's integration stopped: " + r.message);
    const Eigen::MatrixXd& s = r.trajectory.states;
    for (int k = 1; k <= kChunk; ++k) {
      const double change = (s.row(k) - s.row(k - 1)).lpNorm<Eigen::Infinity>();
      if (change <= start.settle_tolerance * std::max(1.0, s.row(k).lpNorm<Eigen::Infinity>())) {
        *periods = done + k;
        return s.row(k).transpose();
      }
    }
    y = s.row(kChunk).transpose();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    if (seconds > start.max_seconds) {
      char budget[32];
      std::snprintf(budget, sizeof budget, "%g s", start.max_seconds);
      throw std::runtime_error("the motion did not settle within " + std::string(budget) + " (" +
                               std::to_string(done + kChunk) + " periods): not periodic at this forcing?");
    }
  }
  throw std::runtime_error("the motion did not settle within " + std::to_string(start.max_periods) +
                           " periods: not periodic at this forcing?");
}

Eigen::VectorXd ForcedRecordStart(const Model& model, seeding::RecordOptions* record, int* periods) {
  *periods = 0;
  if (model.problem.frequencies.size() == 1) {
    const Eigen::VectorXd y = SettledState(model, StartOptions{}, periods);
    record->transient = 0;
    return y;
  }
  if (!model.original) return model.initial_state;
  try {
    const double settled = TorusSettleTime(model, StartOptions{}, periods);
    if (settled > record->transient) {
      record->t_end += settled - record->transient;
      record->transient = settled;
    } else {
      *periods = 0;
    }
  } catch (const std::runtime_error&) {
    *periods = 0;  // the record as it was
  }
  return model.initial_state;
}

double TorusSettleTime(const Model& model, const StartOptions& start, int* periods) {
  if (!model.original) throw std::runtime_error("two motions side by side need explicit ODEs");
  const integrators::OdeSystem one = model.original(model.problem.frequencies);
  const int n = one.dimension;
  integrators::OdeSystem both{2 * n, [one, n](double t, const double* y, double* ydot) {
                                one.rhs(t, y, ydot);
                                one.rhs(t, y + n, ydot + n);
                              }};
  const Eigen::VectorXd& y0 = model.initial_state;
  Eigen::VectorXd y(2 * n);
  y << y0, (y0.array() + 0.1 * std::max(1.0, y0.cwiseAbs().maxCoeff())).matrix();
  const double T = 2 * M_PI / *std::min_element(model.problem.frequencies.begin(), model.problem.frequencies.end());
  const integrators::IntegratorOptions io = SettleIntegration(model);
  const auto begin = std::chrono::steady_clock::now();
  constexpr int kChunk = 25;
  for (int done = 0; done < start.max_periods; done += kChunk) {
    std::vector<double> times;
    for (int k = 1; k <= kChunk; ++k) times.push_back((done + k) * T);
    const integrators::IntegrationResult r = integrators::IntegrateOde(both, y, done * T, times, io);
    if (!r.ok()) throw std::runtime_error("the two motions' integration stopped: " + r.message);
    const Eigen::MatrixXd& s = r.trajectory.states;
    for (int k = 0; k < kChunk; ++k) {
      const double gap = (s.row(k).head(n) - s.row(k).tail(n)).lpNorm<Eigen::Infinity>();
      if (gap <= start.settle_tolerance * std::max(1.0, s.row(k).head(n).lpNorm<Eigen::Infinity>())) {
        *periods = done + k + 1;
        return *periods * T;
      }
    }
    y = s.row(kChunk - 1).transpose();
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count() > start.max_seconds)
      throw std::runtime_error("two motions did not meet within " + std::to_string(done + kChunk) +
                               " periods: another attractor, or not quasi-periodic?");
  }
  throw std::runtime_error("two motions did not meet within " + std::to_string(start.max_periods) + " periods");
}

namespace {

// Where an autonomous motion's returns to a Poincare section settle.
struct SettledReturns {
  double time = 0;     // after the start
  int returns = 0;     // counted from the start
  Eigen::VectorXd state;
};

// Follows the returns from y (its section: through y, normal to the flow)
// until two in a row agree to settle_tolerance max(1, |y|). nullopt when
// they do not within the budget (a torus, chaos: 2000 returns, 300 without
// the gap halving, 2 s; a Van der Pol cycle at mu = 0.01 halves it every
// ~11 returns near the cycle, but from x = 1 at mu = 0.002 the gap grows
// for over 100 first), when there are none (the chunk of 25 guessed
// periods grows first, for a guess far too high), or when the integration
// fails.
std::optional<SettledReturns> SettleReturns(const integrators::OdeSystem& ode, Eigen::VectorXd y, double period,
                                            const integrators::IntegratorOptions& io) {
  constexpr int kMaxReturns = 2000, kMaxWithoutProgress = 300;
  constexpr double kMaxSeconds = 2;
  const double tolerance = StartOptions{}.settle_tolerance;
  const auto begin = std::chrono::steady_clock::now();
  double horizon = 25 * period, t = 0, best_gap = INFINITY;
  for (int returns = 0, without_progress = 0; returns < kMaxReturns && without_progress < kMaxWithoutProgress;) {
    integrators::IntegrationResult info;
    const std::vector<double> times = integrators::SectionReturns(ode, y, horizon, io, &info);
    if (!info.ok()) return std::nullopt;
    if (times.empty()) {
      if ((horizon *= 8) > 1e4 * period) return std::nullopt;
      continue;
    }
    for (int k = 0; k < static_cast<int>(times.size()); ++k, ++returns) {
      const Eigen::VectorXd next = info.trajectory.states.row(k).transpose();
      const double gap = (next - y).lpNorm<Eigen::Infinity>();
      if (gap <= tolerance * std::max(1.0, next.lpNorm<Eigen::Infinity>()))
        return SettledReturns{t + times[k], returns + 1, next};
      if (gap <= 0.5 * best_gap) best_gap = gap, without_progress = 0;
      else ++without_progress;
      y = next;
    }
    t += times.back();
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count() > kMaxSeconds)
      return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace

void SettleAutonomousRecord(const Model& model, const Eigen::VectorXd& y0, seeding::RecordOptions* record,
                            int* periods) {
  *periods = 0;
  if (!model.original || model.problem.frequencies.size() != 1 || y0.size() == 0) return;
  const integrators::OdeSystem ode = model.original(model.problem.frequencies);
  const integrators::IntegratorOptions io = SettleIntegration(model);
  const double w = model.problem.frequencies[0];
  try {
    const integrators::IntegrationResult r = integrators::IntegrateOde(ode, y0, 0, {record->transient}, io);
    if (!r.ok()) return;
    const std::optional<SettledReturns> settled =
        SettleReturns(ode, r.trajectory.states.row(0).transpose(), 2 * M_PI / w, io);
    // Settled by the default transient: the record as it was.
    if (!settled || settled->returns == 1) return;
    // Returns that close in on an equilibrium (a damped motion) settle on no
    // cycle: that record stays as it was too.
    Eigen::VectorXd flow(settled->state.size());
    ode.rhs(0, settled->state.data(), flow.data());
    const double size = std::max(1.0, settled->state.lpNorm<Eigen::Infinity>());
    if (flow.lpNorm<Eigen::Infinity>() <= 1e-6 * w * size) return;
    record->t_end += settled->time;
    record->transient += settled->time;
    *periods = settled->returns;
  } catch (const std::exception&) {
    // A model the integrator refuses keeps its record; the record reports it.
  }
}

StartedSolve SolveFromAnyStart(const Model& model, const HarmonicSolution& guess,
                               const HarmonicBalanceOptions& options, const StartOptions& start) {
  if (const std::string error = start.IsValid(); !error.empty()) throw std::invalid_argument("start: " + error);
  // A forced model whose guess fails at the start order tries the settled
  // motion before the order is raised from the guess (2x, 4x, 8x with
  // Levenberg-Marquardt at each): a user's forced pendulum without a guess
  // spent 1.5 s there, where the simulated start took 0.17 s. The raised
  // orders stay the last resort.
  const bool forced = !Unknown(model.problem) && model.problem.frequencies.size() == 1 &&
                      (model.original || model.original_dae);
  HarmonicBalanceOptions first_try = options;
  if (forced) first_try.raise_order_on_failure = false;
  StartedSolve out{SolveHarmonicBalance(model.problem, guess, first_try), "guess", "", 0};
  // Short of the target but physical and close to it: another start would
  // not do better. Far from it (Van der Pol at eps = 20 from a cosine: order
  // 20, estimated error 1.6e2), the orbit found is not yet the orbit.
  const HarmonicBalanceSummary& first = out.summary;
  const bool far = first.short_of_target && first.truncation_estimate > kFarFromTarget;
  const bool keep = !far && (first.usable() || (first.short_of_target && first.physical));
  if (keep && forced && ConstantInTime(*first.solution)) {
    if (std::optional<StartedSolve> moving = MovingAttractor(model, options, start, &out)) return *moving;
  }
  if (keep || (!model.original && !model.original_dae)) return out;
  out.note = "from the guess: " + WhyNotKept(out.summary);
  // The orbit on a sub-multiple of its frequency: restated on its own.
  if (out.summary.repeats > 1 && out.summary.solution) {
    HarmonicBalanceSummary lifted =
        SolveHarmonicBalance(model.problem, out.summary.solution->OnMultipleFrequency(out.summary.repeats), options);
    if (lifted.usable())
      return {std::move(lifted), "guess, restated on " + std::to_string(out.summary.repeats) + " w", out.note, 0};
    out.note += "; restated on " + std::to_string(out.summary.repeats) + " w: " + WhyNotKept(lifted);
  }
  std::string why;
  // A forced torus does not settle stroboscopically: like an unknown
  // frequency, its trajectory is identified (on the known bases) and seeds it.
  if (Unknown(model.problem) || model.problem.frequencies.size() > 1) {
    AnalyzeOptions analyze;
    analyze.solve = options;
    const AnalyzeSummary a = Analyze(model, analyze);
    if (a.solve && a.solve->usable()) {
      std::string route = "identification";
      if (a.trajectory && a.trajectory->rest_perturbation != 0) {
        char from[96];
        std::snprintf(from, sizeof from, " (recorded from the start + %g: the start is an equilibrium)",
                      a.trajectory->rest_perturbation);
        route += from;
      }
      return {*a.solve, route, out.note, 0};
    }
    out.note += "; from identification: " + std::string(ToString(a.status)) + " " + a.message;
    return out;
  }
  try {
    int periods = 0;
    const Eigen::VectorXd y = SettledState(model, start, &periods);
    if (auto solved = SolveFromRecord(model, y, options, &why))
      return {*solved, "simulation (" + std::to_string(periods) + " periods to settle)", out.note, periods};
    out.note += "; from the simulated start (" + std::to_string(periods) + " periods to settle): " + why;
  } catch (const std::runtime_error& e) {
    out.note += "; simulated start: " + std::string(e.what());
  }
  if (!forced || out.summary.converged() || !options.raise_order_on_failure) return out;
  HarmonicBalanceSummary raised = SolveHarmonicBalance(model.problem, guess, options);
  if (raised.usable()) return {std::move(raised), "guess at a raised order", out.note, 0};
  out.note += "; from the guess at raised orders: " + WhyNotKept(raised);
  out.summary = std::move(raised);
  return out;
}

}  // namespace rmhb

#include "rmhb/pipeline/torus.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "integrators/cvode_integrator.h"
#include "integrators/lyapunov.h"
#include "rmhb/branch_switching.h"

namespace rmhb {
namespace {

// Coefficient column of harmonic index i (>= 1): cos at 2i - 1, sin at 2i.
int CosColumn(int i) { return 2 * i - 1; }

// Whether k leaves the set when |k_b| grows by two for some base b: the two
// outermost layers of the set, whatever its shape (two, so that a set or a
// solution with one parity of harmonics, odd m + n, still has its rim).
bool OnRim(const HarmonicBasis& basis, std::vector<int> k) {
  for (size_t b = 0; b < k.size(); ++b) {
    const int old = k[b];
    for (int step : {-2, 2}) {
      if (old != 0 && (step > 0) != (old > 0)) continue;  // only outward
      k[b] = old + step;
      const bool outside = basis.Find(k) < 0;
      k[b] = old;
      if (outside) return true;
    }
  }
  return false;
}

// How far the integrated trajectory got from the torus it started on.
// states.row(i) is the trajectory at times[i].
void MeasureDeparture(const Model& model, const HarmonicSolution& torus, const Eigen::MatrixXd& states,
                      const std::vector<double>& times, TorusStabilityReport* out) {
  double size = 0;
  std::vector<Eigen::VectorXd> on_torus;
  for (long i = 0; i < states.rows(); ++i) {
    on_torus.push_back(model.state(torus, times[i]));
    size = std::max(size, on_torus.back().cwiseAbs().maxCoeff());
  }
  for (long i = 0; i < states.rows(); ++i) {
    const double d = (states.row(i).transpose() - on_torus[i]).cwiseAbs().maxCoeff() / std::max(size, 1e-300);
    if (d > TorusStabilityReport::kLeftTorus && out->departure <= TorusStabilityReport::kLeftTorus)
      out->left_at = times[i];
    out->departure = std::max(out->departure, d);
  }
}

// The variational integration failed. From a repelling torus the trajectory
// may run off to infinity within one segment (Rayleigh's oscillator reversed
// in time: 5 % off the torus at a segment end, a non-finite right-hand side
// before the next), so the segment ends alone need not show that it left.
// The state alone again, seen eight times per segment up to the failure.
void DepartureBeforeFailure(const Model& model, const HarmonicSolution& torus, const integrators::OdeSystem& system,
                            const integrators::LyapunovOptions& lyapunov, double failed_at,
                            TorusStabilityReport* out) {
  std::vector<double> times;
  const double step = lyapunov.segment / 8;
  for (double t = step; t < failed_at + lyapunov.segment; t += step) times.push_back(t);
  const integrators::IntegrationResult plain =
      integrators::IntegrateOde(system, model.state(torus, 0.0), 0.0, times, lyapunov.integrator);
  const std::vector<double> reached(times.begin(), times.begin() + plain.trajectory.states.rows());
  MeasureDeparture(model, torus, plain.trajectory.states, reached, out);
}

}  // namespace

double OutermostCoefficients(const HarmonicSolution& s) {
  const HarmonicBasis& basis = s.basis();
  std::vector<bool> outer(basis.size(), false);
  for (int i = 1; i < basis.size(); ++i) outer[i] = OnRim(basis, basis.harmonic(i));
  double worst = 0;
  const Eigen::MatrixXd& c = s.coefficients();
  for (int v = 0; v < s.num_variables(); ++v) {
    double all = 0, edge = 0;
    for (int i = 1; i < basis.size(); ++i) {
      const double size = c.row(v).segment(CosColumn(i), 2).squaredNorm();
      all += size;
      if (outer[i]) edge += size;
    }
    if (all > 0) worst = std::max(worst, std::sqrt(edge / all));
  }
  return worst;
}

std::string TorusStabilityOptions::IsValid() const {
  if (!(periods > 0) || !std::isfinite(periods)) return "periods must be finite and > 0";
  if (!(segment_periods > 0) || segment_periods > periods) return "segment_periods must be in (0, periods]";
  if (!(relative_tolerance > 0) || !(tolerance > 0)) return "tolerances must be > 0";
  return "";
}

std::string TorusStabilityReport::BriefReport() const {
  if (!ok) return "Lyapunov exponents: " + message;
  std::string out = ToString(stability);
  char text[160];
  std::snprintf(text, sizeof text, " (Lyapunov: largest non-trivial exponent %.3g, tolerance %.1e; %d trivial, max |.| %.1e), exponents",
                max_exponent, tolerance, trivial, trivial_max);
  out += text;
  for (double l : exponents) std::snprintf(text, sizeof text, " %.6g", l), out += text;
  std::snprintf(text, sizeof text, "; off the torus %.1e; t = %.4g, %ld steps, %.3g ms", departure, time, steps,
                seconds * 1e3);
  out += text;
  if (!message.empty()) out += "; " + message;
  return out;
}

TorusStabilityReport TorusStability(const Model& model, const HarmonicSolution& torus,
                                    const TorusStabilityOptions& options) {
  if (const std::string why = options.IsValid(); !why.empty()) throw std::invalid_argument("TorusStability: " + why);
  const std::vector<double>& w = torus.frequencies();
  if (w.size() < 2) throw std::invalid_argument("TorusStability: a periodic solution is not a torus");
  TorusStabilityReport out;
  if (!model.original) {
    out.message = model.original_dae ? "a DAE model (Lyapunov exponents integrate ODEs)"
                                     : "no original equations: " + model.original_error;
    return out;
  }
  const double w_min = *std::min_element(w.begin(), w.end());
  const double period = 2 * M_PI / w_min;
  integrators::LyapunovOptions lyapunov;
  lyapunov.integrator.relative_tolerance = options.relative_tolerance;
  lyapunov.integrator.absolute_tolerance = 1e-3 * options.relative_tolerance;
  if (model.stiff) lyapunov.integrator.method = integrators::IntegratorOptions::Method::kBdf;
  lyapunov.segment = period * options.segment_periods;
  lyapunov.segments = std::max(2, static_cast<int>(std::ceil(options.periods / options.segment_periods)));
  const integrators::OdeSystem system = model.original(w);
  const integrators::LyapunovReport r = integrators::LyapunovExponents(system, model.state(torus, 0.0), 0.0, lyapunov);
  out.ok = r.ok;
  out.time = r.time;
  out.steps = r.steps;
  out.seconds = r.seconds;
  if (!r.ok) {
    out.message = "integration failed: " + r.message;
    DepartureBeforeFailure(model, torus, system, lyapunov, r.time, &out);
    if (out.departure > TorusStabilityReport::kLeftTorus) {
      char text[160];
      std::snprintf(text, sizeof text, "the trajectory left the torus (|y - torus| %.2g of its size at t = %.4g): it repels; ",
                    out.departure, out.left_at);
      out.message = text + out.message;
      out.stability = PointStability::kUnstable;
    }
    return out;
  }
  out.exponents = r.exponents;
  out.spread = r.spread;
  std::vector<double> ends;
  for (long i = 0; i < r.segment_states.rows(); ++i) ends.push_back((i + 1) * lyapunov.segment);
  MeasureDeparture(model, torus, r.segment_states, ends, &out);
  out.tolerance = std::max(options.tolerance * w_min, 3 * r.spread);
  // The free angles: the unknown bases (a forced torus' angle along the
  // forcing is time itself, not a state direction).
  out.trivial = std::min(torus.basis().num_bases(), model.problem.num_unknown_frequencies());
  std::vector<double> by_size = r.exponents;
  std::sort(by_size.begin(), by_size.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
  out.trivial_max = out.trivial > 0 ? std::abs(by_size[out.trivial - 1]) : 0;
  out.max_exponent = -HUGE_VAL;
  for (size_t i = out.trivial; i < by_size.size(); ++i) out.max_exponent = std::max(out.max_exponent, by_size[i]);
  if (by_size.size() == static_cast<size_t>(out.trivial)) out.max_exponent = 0;
  out.stability = out.max_exponent < -out.tolerance  ? PointStability::kStable
                  : out.max_exponent > out.tolerance ? PointStability::kUnstable
                                                     : PointStability::kNeutral;
  if (out.departure > TorusStabilityReport::kLeftTorus) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "the trajectory left the torus (|y - torus| %.2g of its size at t = %.4g): it repels; the "
                  "exponents are the trajectory's, not the torus'",
                  out.departure, out.left_at);
    out.message = text;
    out.stability = PointStability::kUnstable;
  } else if (out.trivial_max > out.tolerance) {
    char text[200];
    std::snprintf(text, sizeof text, "the %d exponents closest to 0 should vanish on a torus but reach %.2e > %.1e",
                  out.trivial, out.trivial_max, out.tolerance);
    out.message = text;
    out.stability = PointStability::kUnknown;
  }
  return out;
}

Resonance NearestResonance(double ratio, int max_denominator) {
  if (max_denominator < 1 || !std::isfinite(ratio))
    throw std::invalid_argument("NearestResonance: need a finite ratio and max_denominator >= 1");
  Resonance best{static_cast<int>(std::lround(ratio)), 1, std::abs(ratio - std::round(ratio))};
  for (int q = 2; q <= max_denominator; ++q) {
    const int p = static_cast<int>(std::lround(ratio * q));
    const double d = std::abs(ratio - static_cast<double>(p) / q);
    if (d < best.distance - 1e-15) best = {p, q, d};
  }
  return best;
}

bool IsForcedTorus(const Model& model) {
  const HarmonicBalanceProblem& p = model.problem;
  return p.frequencies.size() == 2 && p.num_unknown_frequencies() == 1 && !p.unknown_frequency[0];
}

bool IsAutonomousTorus(const Model& model) {
  const HarmonicBalanceProblem& p = model.problem;
  return p.frequencies.size() == 2 && p.num_unknown_frequencies() == 2;
}

int LockedPeriods(const Model& model, int transient, int max_denominator, double tolerance, double* mismatch) {
  if (!IsForcedTorus(model)) throw std::invalid_argument("LockedPeriods: not a forced torus");
  if (transient < 0 || max_denominator < 1 || !(tolerance > 0))
    throw std::invalid_argument("LockedPeriods: need transient >= 0, max_denominator >= 1, tolerance > 0");
  const double T = 2 * M_PI / model.problem.frequencies[0];
  const int kept = 4 * max_denominator;
  std::vector<double> times;
  for (int k = 0; k < kept; ++k) times.push_back((transient + k) * T);
  integrators::IntegratorOptions io;
  io.relative_tolerance = 1e-11;
  io.absolute_tolerance = 1e-13;
  if (model.stiff) io.method = integrators::IntegratorOptions::Method::kBdf;
  const integrators::IntegrationResult r =
      SimulateOriginal(model, model.problem.frequencies, model.initial_state, times, io);
  *mismatch = HUGE_VAL;
  if (!r.ok()) return 0;
  const Eigen::MatrixXd& y = r.trajectory.states;
  const double scale = std::max(y.cwiseAbs().maxCoeff(), 1e-300);
  for (int q = 1; q <= max_denominator; ++q) {
    double worst = 0;
    for (int k = kept - 3 * max_denominator; k + q < kept; ++k)
      worst = std::max(worst, (y.row(k + q) - y.row(k)).lpNorm<Eigen::Infinity>() / scale);
    if (worst <= tolerance) {
      *mismatch = worst;
      return q;
    }
    *mismatch = std::min(*mismatch, worst);
  }
  return 0;
}

Resonance LockedResonance(const HarmonicSolution& locked, int q) {
  int best = 1;
  double largest = -1;
  for (int i = 1; i < locked.basis().size(); ++i) {
    const double a = locked.coefficients().row(0).segment(CosColumn(i), 2).norm();
    if (a > largest) largest = a, best = locked.basis().harmonic(i)[0];
  }
  return {best, q, 0};
}

Model LockedModel(const Model& model, const Resonance& lock) {
  const HarmonicBalanceProblem& problem = model.problem;
  const bool forced = IsForcedTorus(model);
  if (!forced && !IsAutonomousTorus(model))
    throw std::invalid_argument(
        "locking: a torus has two bases, the first known (the forcing) and the second unknown, or both unknown");
  if (lock.q < 1 || lock.p < 1) throw std::invalid_argument("locking: need p, q >= 1");
  const int free_angles = forced ? 1 : 2;
  if (model.num_user_conditions < free_angles)
    throw std::invalid_argument("locking: the model has fewer conditions than the torus has free angles");
  Model out = model;
  out.problem = OnResonantBase(problem, {lock.q, lock.p});
  // A forced torus' one user condition fixed its free angle; the locked
  // orbit's phase is the forcing's. An autonomous torus' two fixed both
  // angles; the locked orbit has one phase, fixed by the first of them.
  out.problem.conditions.erase(out.problem.conditions.begin() + (forced ? 0 : 1));
  out.num_user_conditions = model.num_user_conditions - 1;
  const auto bind = [lock](const std::vector<double>& w) {
    return std::vector<double>{w[0] * lock.q, w[0] * lock.p};
  };
  if (model.original) out.original = [original = model.original, bind](const std::vector<double>& w) { return original(bind(w)); };
  if (model.original_dae)
    out.original_dae = [original = model.original_dae, bind](const std::vector<double>& w) { return original(bind(w)); };
  if (model.variables)
    out.variables = [variables = model.variables, lock](const std::vector<double>& theta,
                                                        const std::vector<Eigen::VectorXd>& state) {
      return variables({lock.q * theta[0], lock.p * theta[0]}, state);
    };
  const int order = model.default_order;
  out.guess = nullptr;
  out.default_order = order * std::max(lock.p, lock.q);
  out.reload = nullptr;
  out.reload_problem = nullptr;
  out.frequency_parameters.clear();
  out.reference = {};
  out.invariances.clear();
  return out;
}

HarmonicSolution LockedSolution(const HarmonicSolution& torus, const Resonance& lock, double phase) {
  if (torus.basis().num_bases() != 2) throw std::invalid_argument("LockedSolution: a torus on two bases");
  const HarmonicSolution s = torus.Shifted({0.0, phase});
  const HarmonicBasis& basis = s.basis();
  int order = 0;
  for (const auto& k : basis.harmonics()) order = std::max(order, std::abs(k[0] * lock.q + k[1] * lock.p));
  const HarmonicBasis periodic = HarmonicBasis::Periodic(std::max(order, 1));
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(s.num_variables(), periodic.num_coefficients());
  c.col(0) = s.coefficients().col(0);
  for (int i = 1; i < basis.size(); ++i) {
    const int k = basis.harmonic(i)[0] * lock.q + basis.harmonic(i)[1] * lock.p;
    const Eigen::MatrixXd ab = s.coefficients().middleCols(CosColumn(i), 2);
    if (k == 0) {
      c.col(0) += ab.col(0);
      continue;
    }
    const int j = periodic.Find({std::abs(k)});
    c.col(CosColumn(j)) += ab.col(0);
    c.col(CosColumn(j) + 1) += (k > 0 ? 1.0 : -1.0) * ab.col(1);
  }
  return HarmonicSolution(periodic, {s.frequencies()[0] / lock.q}, c, s.variables());
}

}  // namespace rmhb

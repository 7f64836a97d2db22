#ifndef RMHB_TESTS_PIPELINE_SHOOTING_H_
#define RMHB_TESTS_PIPELINE_SHOOTING_H_

// Brute-force references for bifurcations that use no harmonic balance:
// the periodic orbit of a model's original equations by shooting (Newton on
// phi_T(y) - y with the CVODE monodromy matrix, rtol 1e-12), its Floquet
// multipliers, and the parameter where one crosses the unit circle by the
// secant method on them; for a model with switches (max, ...) the
// integration locates them by root finding. Used by tests/pipeline/branch_test.cc and
// tests/benchmarks/bifurcation_benchmark.cc; the period of a limit cycle
// by its zero crossings (studies_test.cc, pipeline_test.cc).

#include <cmath>
#include <complex>
#include <vector>

#include <Eigen/Dense>

#include "integrators/cvode_integrator.h"
#include "integrators/event_detection.h"
#include "integrators/floquet.h"
#include "integrators/switched_integration.h"
#include "rmhb/pipeline/model.h"

namespace rmhb::testing {

struct Orbit {
  Eigen::VectorXd y;                       // the state at t = 0
  std::vector<std::complex<double>> mu;    // Floquet multipliers
};

// phi_T(y) and the monodromy matrix of the model's original equations
// forced at w; with switches (max, min, abs, ...) located by root finding
// (IntegrateSwitched, SwitchedMonodromy: exact for continuous forces). false
// when the integration fails.
inline bool FlowAndMonodromy(const Model& model, double w, const Eigen::VectorXd& y, double T, Eigen::VectorXd* end,
                             Eigen::MatrixXd* monodromy) {
  integrators::IntegratorOptions tight;  // Adams, rtol 1e-12
  if (model.original_switched) {
    const integrators::SwitchedOdeSystem ode = model.original_switched({w});
    const integrators::SwitchedIntegration r = integrators::IntegrateSwitched(ode, y, 0.0, {T}, tight);
    if (!r.result.ok()) return false;
    *end = r.result.trajectory.states.row(0).transpose();
    std::string failure;
    *monodromy = integrators::SwitchedMonodromy(ode, y, T, tight, &failure);
    return failure.empty() && monodromy->size() > 0;
  }
  const integrators::OdeSystem ode = model.original({w});
  const integrators::IntegrationResult r = integrators::IntegrateOde(ode, y, 0.0, {T}, tight);
  if (!r.ok()) return false;
  *end = r.trajectory.states.row(0).transpose();
  *monodromy = integrators::FloquetMultipliers(ode, y, 0.0, T).monodromy;
  return true;
}

// The orbit of period multiple * 2 pi / w of the model's original equations
// forced at w, by Newton on phi_T(y) - y from y; no multipliers when Newton
// does not converge (near a turning point a multiplier near 1 makes it
// wander: a crossing "located" on such orbits was 1e-14 from the start).
inline Orbit Shoot(const Model& model, double w, Eigen::VectorXd y, int multiple = 1) {
  const double T = multiple * 2 * M_PI / w;
  Eigen::VectorXd end;
  Eigen::MatrixXd monodromy;
  bool converged = false;
  for (int it = 0; it < 30 && !converged; ++it) {
    if (!FlowAndMonodromy(model, w, y, T, &end, &monodromy)) return {y, {}};
    const Eigen::MatrixXd A = monodromy - Eigen::MatrixXd::Identity(y.size(), y.size());
    const Eigen::VectorXd step = A.partialPivLu().solve(end - y);
    y -= step;
    converged = step.norm() <= 1e-11 * (1 + y.norm());
  }
  if (!converged || !FlowAndMonodromy(model, w, y, T, &end, &monodromy)) return {y, {}};
  const Eigen::VectorXcd mu = Eigen::EigenSolver<Eigen::MatrixXd>(monodromy, false).eigenvalues();
  return {y, std::vector<std::complex<double>>(mu.data(), mu.data() + mu.size())};
}

// Signed distance from the crossing: the real multiplier nearest -1 (mu + 1)
// or the complex one nearest the unit circle (|mu| - 1).
inline double Distance(const std::vector<std::complex<double>>& mu, bool period_doubling) {
  double best = HUGE_VAL;
  for (const auto& m : mu) {
    const bool real = std::abs(m.imag()) <= 1e-9 * (1 + std::abs(m));
    if (period_doubling && real && std::abs(m.real() + 1) < std::abs(best)) best = m.real() + 1;
    if (!period_doubling && !real && std::abs(std::abs(m) - 1) < std::abs(best)) best = std::abs(m) - 1;
  }
  return best;
}

// The parameter w in [a, b] where the multipliers cross, by the Illinois
// method (regula falsi that halves the stale end's value) on the shooting
// orbit's multipliers, so that it never leaves the bracket (a plain secant
// once ran off to w = 5e5), and only onto a point where they cross (|g| <=
// 1e-6); *y follows the orbit. Where the critical
// multiplier is not of its kind at b (a complex pair not yet split into the
// real one that crosses -1), b moves halfway to a first. NAN: no crossing.
inline double ReferenceCrossing(const Model& model, double a, double b, bool period_doubling, Eigen::VectorXd* y) {
  Orbit oa = Shoot(model, a, *y);
  Orbit ob = Shoot(model, b, oa.y);
  double ga = Distance(oa.mu, period_doubling), gb = Distance(ob.mu, period_doubling);
  for (int i = 0; i < 20 && !std::isfinite(gb); ++i) {
    b = 0.5 * (a + b);
    ob = Shoot(model, b, oa.y);
    gb = Distance(ob.mu, period_doubling);
  }
  if (!(ga * gb < 0)) return NAN;  // no crossing in [a, b]
  int stale = 0;                   // which end kept its value last: -1 a, +1 b
  for (int it = 0; it < 60 && std::abs(b - a) > 1e-13; ++it) {
    const double c = b - gb * (b - a) / (gb - ga);
    const Orbit oc = Shoot(model, c, ob.y);
    const double gc = Distance(oc.mu, period_doubling);
    if (!std::isfinite(gc)) return NAN;  // an orbit lost on the way (no multipliers)
    if (gc == 0) return *y = oc.y, c;
    if (gc * gb < 0) {
      a = b, ga = gb;  // the crossing lies between c and the old b
      stale = 0;
    } else if (stale == -1) {
      ga *= 0.5;       // a stayed twice: Illinois
    } else {
      stale = -1;
    }
    b = c, gb = gc, ob = oc;
    if (std::abs(gb) <= 1e-12) break;
  }
  // A bracket that closed on a jump of the multipliers (the orbit lost past a
  // turning point) is no crossing.
  if (!(std::abs(gb) <= 1e-6)) return NAN;
  *y = ob.y;
  return b;
}

// The period of a self-excited model's limit cycle: CVODE (rtol 1e-13) from
// its initial state to t_end, the mean spacing of the upward zero crossings
// of its first state after the first 20 (integrators::LimitCyclePeriod).
inline double LimitCyclePeriodOf(const Model& model, double t_end = 400) {
  integrators::IntegratorOptions tight;
  tight.relative_tolerance = 1e-13;
  tight.absolute_tolerance = 1e-15;
  return integrators::LimitCyclePeriod(model.original(model.problem.frequencies), model.initial_state, t_end,
                                       [](double, const double* y) { return y[0]; }, +1, 20, tight);
}

}  // namespace rmhb::testing

#endif  // RMHB_TESTS_PIPELINE_SHOOTING_H_

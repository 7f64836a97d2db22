#ifndef RMHB_TESTS_PIPELINE_SHOOTING_H_
#define RMHB_TESTS_PIPELINE_SHOOTING_H_

// Brute-force references for bifurcations that use no harmonic balance:
// the periodic orbit of a model's original equations by shooting (Newton on
// phi_T(y) - y with the CVODE monodromy matrix, rtol 1e-12), its Floquet
// multipliers, and the parameter where one crosses the unit circle by the
// secant method on them. Used by tests/pipeline/branch_test.cc and
// tests/benchmarks/bifurcation_benchmark.cc.

#include <cmath>
#include <complex>
#include <vector>

#include <Eigen/Dense>

#include "integrators/cvode_integrator.h"
#include "integrators/floquet.h"
#include "rmhb/pipeline/model.h"

namespace rmhb::testing {

struct Orbit {
  Eigen::VectorXd y;                       // the state at t = 0
  std::vector<std::complex<double>> mu;    // Floquet multipliers
};

// The orbit of period multiple * 2 pi / w of the model's original equations
// forced at w, by Newton on phi_T(y) - y from y.
inline Orbit Shoot(const Model& model, double w, Eigen::VectorXd y, int multiple = 1) {
  const integrators::OdeSystem ode = model.original({w});
  const double T = multiple * 2 * M_PI / w;
  integrators::IntegratorOptions tight;  // Adams, rtol 1e-12
  for (int it = 0; it < 30; ++it) {
    const integrators::IntegrationResult r = integrators::IntegrateOde(ode, y, 0.0, {T}, tight);
    if (!r.ok()) return {y, {}};
    const Eigen::VectorXd end = r.trajectory.states.row(0).transpose();
    const integrators::FloquetReport f = integrators::FloquetMultipliers(ode, y, 0.0, T);
    const Eigen::MatrixXd A = f.monodromy - Eigen::MatrixXd::Identity(y.size(), y.size());
    const Eigen::VectorXd step = A.partialPivLu().solve(end - y);
    y -= step;
    if (step.norm() <= 1e-13 * (1 + y.norm())) break;
  }
  return {y, integrators::FloquetMultipliers(ode, y, 0.0, T).multipliers};
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

// The parameter w in [a, b] where the multipliers cross, by the secant
// method on the shooting orbit's multipliers; *y follows the orbit. Where
// the critical multiplier is not of its kind at b (a complex pair not yet
// split into the real one that crosses -1), b moves halfway to a first.
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
  for (int it = 0; it < 30 && std::abs(b - a) > 1e-13; ++it) {
    const double c = b - gb * (b - a) / (gb - ga);
    const Orbit oc = Shoot(model, c, ob.y);
    a = b, ga = gb, b = c, gb = Distance(oc.mu, period_doubling), ob = oc;
  }
  *y = ob.y;
  return b;
}

}  // namespace rmhb::testing

#endif  // RMHB_TESTS_PIPELINE_SHOOTING_H_

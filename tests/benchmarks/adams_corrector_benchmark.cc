// Adams corrector choice: fixed-point iteration vs. dense Newton with a
// finite-difference Jacobian, on the pendulum theta'' = -sin(theta) from
// theta0 = 1.5 at rest, integrated over 10 periods, where the exact state
// returns to (1.5, 0). Also prints the error against relative_tolerance to
// locate the practical tolerance floor.
//
// Run: build/adams_corrector_benchmark

#include <cvode/cvode.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "integrators/cvode_integrator.h"
#include "integrators/detail/cvode_session.h"
#include "tests/integrators/test_systems.h"

namespace {

using rmhb::integrators::IntegratorOptions;
using rmhb::integrators::OdeSystem;
using rmhb::integrators::testing::Pendulum;
constexpr double kPeriod = rmhb::integrators::testing::kPendulumPeriod;
using rmhb::integrators::detail::AdamsCorrector;
using rmhb::integrators::detail::CvodeSession;

void Run(const char* label, AdamsCorrector corrector, double rtol, double atol) {
  const OdeSystem system = Pendulum();
  Eigen::VectorXd y0(2);
  y0 << 1.5, 0.0;
  IntegratorOptions options;
  options.relative_tolerance = rtol;
  options.absolute_tolerance = atol;
  constexpr int kRepeats = 5;
  double best = 1e300, error = 0;
  long steps = 0, evals = 0;
  bool ok = true;
  for (int r = 0; r < kRepeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    CvodeSession session(system, y0, 0.0, options, corrector);
    double t = 0;
    ok = session.ok() && session.Advance(10 * kPeriod, &t) >= 0;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    best = std::min(best, seconds);
    error = std::hypot(session.state()[0] - 1.5, session.state()[1]);
    steps = session.steps();
    evals = session.rhs_evaluations();
    if (!ok) std::printf("  failure: %s\n", session.failure().c_str());
  }
  std::printf("%-12s rtol %.0e atol %.0e: %s steps %7ld rhs %8ld  %.2f ms  |error| %.2e\n", label,
              rtol, atol, ok ? "ok  " : "FAIL", steps, evals, 1e3 * best, error);
}

}  // namespace

int main() {
  for (double rtol : {1e-10, 1e-12, 1e-13}) {
    Run("fixed-point", AdamsCorrector::kFixedPoint, rtol, rtol * 1e-2);
    Run("newton", AdamsCorrector::kNewton, rtol, rtol * 1e-2);
  }
  std::printf("tolerance floor (fixed-point corrector):\n");
  for (double rtol : {1e-14, 3e-15, 1e-15, 5e-16, 3e-16, 2.3e-16, 2e-16, 1e-16, 1e-17}) {
    Run("fixed-point", AdamsCorrector::kFixedPoint, rtol, 1e-20);
  }
  return 0;
}

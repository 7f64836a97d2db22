// Every example against a tight SUNDIALS trajectory of its ORIGINAL equations
// (not the recast): the solution's state at t = 0 is integrated over a period
// and compared along the way. This is the independent reference for the
// systems without a closed form (forced Duffing, Rayleigh-Plesset, Van der Pol).

#include <gtest/gtest.h>

#include <cmath>

#include "examples/example_system.h"
#include "integrators/event_detection.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/harmonic_balance.h"

namespace rmhb {
namespace {

struct Case {
  std::string name;
  std::map<std::string, double> parameters;
  int order;
  double tolerance;  // CVODE's accuracy at rtol 1e-13 (Adams) / 1e-12 (BDF) bounds this
};

class ExampleValidation : public ::testing::TestWithParam<Case> {};

TEST_P(ExampleValidation, MatchesIntegratedOriginalEquations) {
  const Case& c = GetParam();
  const examples::ExampleSetup e = examples::BuildExample(c.name, c.parameters);
  HarmonicBalanceOptions o;
  o.order = c.order;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(e.problem, e.guess, o);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  const HarmonicSolution& sol = *s.solution;
  integrators::OdeSystem ode{e.original.dimension(), e.original.rhs};
  const auto report = integrators::ValidateTrajectory(
      ode, [&](double t) { return e.original.state(sol, t); }, 2 * M_PI / sol.frequencies()[0],
      e.original.stiff);
  ASSERT_TRUE(report.ok) << report.message;
  EXPECT_LT(report.max_error, c.tolerance) << c.name << " at t = " << report.error_time;
  // And a truncated solve must be caught: the check can fail.
  HarmonicBalanceOptions coarse = o;
  coarse.order = 3;
  coarse.solver.acceptable_residual = 1e300;
  const HarmonicBalanceSummary bad = SolveHarmonicBalance(e.problem, e.guess, coarse);
  const auto bad_report = integrators::ValidateTrajectory(
      ode, [&](double t) { return e.original.state(*bad.solution, t); },
      2 * M_PI / bad.solution->frequencies()[0], e.original.stiff);
  EXPECT_GT(bad_report.max_error, 100 * c.tolerance) << c.name;
}

INSTANTIATE_TEST_SUITE_P(
    AllExamples, ExampleValidation,
    ::testing::Values(Case{"duffing", {}, 25, 1e-10},
                      Case{"duffing", {{"F", 2.0}, {"w", 1.8}}, 30, 1e-10},
                      Case{"rayleigh-plesset", {}, 40, 1e-10},
                      Case{"pendulum", {{"theta0", 2.5}}, 40, 1e-10},
                      Case{"relativistic", {{"beta", 0.7}}, 50, 1e-10},
                      Case{"vanderpol", {{"eps", 1.0}}, 40, 1e-9},  // limit cycle: CVODE phase drift
                      Case{"vanderpol", {{"eps", 3.0}}, 200, 1e-9}),
    [](const ::testing::TestParamInfo<Case>& info) {
      std::string n = info.param.name + "_" + std::to_string(info.index);
      for (char& ch : n)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return n;
    });

}  // namespace
}  // namespace rmhb

namespace rmhb {
namespace {

// Van der Pol eps = 10 (relaxation): the period from harmonic balance against
// the period CVODE measures between successive maxima of x once the orbit has
// settled on the limit cycle (event detection polished to round-off).
TEST(VanDerPolRelaxation, PeriodMatchesTightCvodeReference) {
  const examples::ExampleSetup e = examples::BuildExample("vanderpol", {{"eps", 10.0}});
  integrators::OdeSystem ode{2, e.original.rhs};
  integrators::IntegratorOptions io;
  io.relative_tolerance = 1e-14;
  io.absolute_tolerance = 1e-16;
  const auto maxima = integrators::FindCrossings(
      ode, Eigen::Vector2d(2.0, 0.0), 0.0, 12 * 19.1,
      [](double, const double* y) { return y[1]; }, -1, io);
  ASSERT_GE(maxima.size(), 8u);
  // x' crosses zero downwards only at the maxima of x: one per period.
  const double cvode_period = maxima[maxima.size() - 1] - maxima[maxima.size() - 2];
  EXPECT_NEAR(cvode_period, 19.07836956693901407, 1e-9);  // CVODE itself, sanity

  HarmonicBalanceOptions o;
  o.order = 340;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(e.problem, e.guess, o);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  const double hb_period = 2 * M_PI / s.solution->frequencies()[0];
  EXPECT_NEAR(hb_period, cvode_period, 1e-10) << "CVODE " << cvode_period;
}

}  // namespace
}  // namespace rmhb

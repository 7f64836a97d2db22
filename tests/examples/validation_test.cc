// Every example against a tight SUNDIALS trajectory of its ORIGINAL equations
// (not the recast): the solution's state at t = 0 is integrated over a period
// and compared along the way. This is the independent reference for the
// systems without a closed form (forced Duffing, Rayleigh-Plesset, Van der Pol).

#include <gtest/gtest.h>

#include <cmath>

#include "examples/example_system.h"
#include "examples/references.h"
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

TEST(VanDerPolRelaxation, CvodeReferenceMatchesThePublishedPeriod) {
  // ../shared/ref/periodic.json (arbitrary-precision Taylor integration).
  EXPECT_NEAR(examples::VanDerPolPeriodByCvode(10.0), 19.07836956693901407, 2e-11);
}

// The simulated starting guess survives the stiffness of eps = 50 (its RK4
// step used to blow up) and starts close to the limit cycle.
TEST(VanDerPolRelaxation, StiffGuessFindsThePeriod) {
  const examples::ExampleSetup e = examples::BuildExample("vanderpol", {{"eps", 50.0}});
  const double guess_period = 2 * M_PI / e.guess.frequencies()[0];
  EXPECT_NEAR(guess_period, examples::VanDerPolPeriodByCvode(50.0), 1e-3 * guess_period);
  EXPECT_NEAR(e.guess.Value(0, 0.0), 2.0, 0.05);  // the guess starts at a maximum of x
}

// eps = 20 (N ~ 1000, 3 s) and 50 (N ~ 6000, minutes): tests/benchmarks/rhb_benchmark.
TEST(VanDerPolRelaxation, PeriodMatchesTightCvodeReference) {
  struct Case {
    double eps;
    int order;
  };
  for (const Case& c : {Case{5.0, 100}, Case{10.0, 300}}) {
    const double reference = examples::VanDerPolPeriodByCvode(c.eps);
    const examples::ExampleSetup e = examples::BuildExample("vanderpol", {{"eps", c.eps}});
    HarmonicBalanceOptions o;
    o.order = c.order;
    const HarmonicBalanceSummary s = SolveHarmonicBalance(e.problem, e.guess, o);
    ASSERT_TRUE(s.converged()) << s.FullReport();
    EXPECT_NEAR(2 * M_PI / s.solution->frequencies()[0], reference, 1e-9) << "eps = " << c.eps;
    // Truncation shows at a lower order: the comparison can fail.
    o.order = c.order / 2;
    const HarmonicBalanceSummary coarse = SolveHarmonicBalance(e.problem, e.guess, o);
    ASSERT_TRUE(coarse.solution.has_value());
    EXPECT_GT(std::abs(2 * M_PI / coarse.solution->frequencies()[0] - reference), 1e-9) << c.eps;
  }
}

// --tol on a relaxation oscillation: the chosen order's period is within the
// tolerance (relative) of CVODE's, and the estimate is not below the error.
TEST(VanDerPolRelaxation, OrderSelectionMeetsTheToleranceAgainstCvode) {
  const double reference = examples::VanDerPolPeriodByCvode(5.0);
  const examples::ExampleSetup e = examples::BuildExample("vanderpol", {{"eps", 5.0}});
  HarmonicBalanceOptions o;
  o.order = 20;
  o.tolerance = 1e-10;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(e.problem, e.guess, o);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  const double error = std::abs(2 * M_PI / s.solution->frequencies()[0] - reference) / reference;
  EXPECT_LE(error, o.tolerance) << "N = " << s.order;
  EXPECT_LE(s.truncation_estimate, o.tolerance);
  // CVODE's own relative accuracy here is ~1e-12: the honesty check needs margin.
  EXPECT_GE(s.truncation_estimate + 2e-12, error) << "N = " << s.order;
}

}  // namespace
}  // namespace rmhb

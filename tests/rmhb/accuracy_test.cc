// Accuracy against exact references (rmhb/METHOD.md s.7): the numbers the paper
// reports are floors to beat.

#include <gtest/gtest.h>

#include <cmath>

#include "examples/example_system.h"
#include "examples/references.h"
#include "rmhb/harmonic_balance.h"

namespace rmhb {
namespace {

HarmonicBalanceSummary Solve(const examples::ExampleSetup& e, int order,
                             SolverMethod method = SolverMethod::kAuto) {
  HarmonicBalanceOptions o;
  o.order = order;
  o.solver.method = method;
  return SolveHarmonicBalance(e.problem, e.guess, o);
}

TEST(References, MatchPublishedValues) {
  // ../shared/ref/periodic.json, computed at 30+ digits elsewhere.
  EXPECT_NEAR(examples::PendulumFrequency(1.5), 0.860608346679612985103549304862, 2e-16);
  EXPECT_NEAR(examples::PendulumCoefficient(1.5, 1), 1.52004746521332765948913464242, 1e-15);
  EXPECT_NEAR(examples::PendulumCoefficient(1.5, 15), -1.43733275301701276344379668908e-11, 1e-24);
  EXPECT_NEAR(examples::RelativisticAmplitude(0.85), 1.34038501297574794295514979307, 1e-15);
  EXPECT_NEAR(examples::RelativisticPeriod(0.85), 8.16220494978763070585185405674, 1e-14);
}

// Paper: N = 25, M = 76, mean error 1.9e-12.
TEST(Accuracy, PendulumBeatsThePaper) {
  const examples::ExampleSetup e = examples::BuildExample("pendulum", {{"theta0", 1.5}});
  for (SolverMethod m : {SolverMethod::kAuto, SolverMethod::kNewton,
                         SolverMethod::kLevenbergMarquardt, SolverMethod::kTikhonov}) {
    const HarmonicBalanceSummary s = Solve(e, 25, m);
    ASSERT_TRUE(s.converged()) << ToString(m) << "\n" << s.FullReport();
    const HarmonicSolution& sol = *s.solution;
    EXPECT_LT(std::abs(sol.frequencies()[0] - examples::PendulumFrequency(1.5)), 1e-13) << ToString(m);
    const double T = 2 * M_PI / sol.frequencies()[0];
    double worst = 0;
    for (int i = 0; i <= 1000; ++i) {
      const double t = T * i / 1000;
      worst = std::max(worst, std::abs(sol.Value(0, t) - examples::PendulumAngle(1.5, t)));
    }
    EXPECT_LT(worst, 2e-12) << ToString(m);
    // The auxiliaries are sin and cos of theta, not just anything that
    // satisfies their derivative equations.
    for (double t : {0.0, 0.3 * T, 0.77 * T}) {
      EXPECT_NEAR(sol.Value(2, t), std::sin(sol.Value(0, t)), 1e-12);
      EXPECT_NEAR(sol.Value(3, t), std::cos(sol.Value(0, t)), 1e-12);
    }
  }
}

// Paper: N = 55, amplitude error 3.87e-12.
TEST(Accuracy, RelativisticBeatsThePaper) {
  const examples::ExampleSetup e = examples::BuildExample("relativistic", {{"beta", 0.85}});
  const HarmonicBalanceSummary s = Solve(e, 55);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  EXPECT_LT(std::abs(s.solution->Amplitude(0) - examples::RelativisticAmplitude(0.85)), 4e-12);
  EXPECT_LT(std::abs(s.solution->frequencies()[0] - 2 * M_PI / examples::RelativisticPeriod(0.85)),
            1e-12);
}

// Error falls geometrically with N until round-off (a convergence rate, not a point).
TEST(Accuracy, PendulumErrorFallsGeometrically) {
  const examples::ExampleSetup e = examples::BuildExample("pendulum", {{"theta0", 1.5}});
  double previous = 1;
  for (int N : {3, 7, 11, 15}) {  // odd harmonics only: two new ones per step
    const HarmonicBalanceSummary s = Solve(e, N);
    ASSERT_TRUE(s.solution.has_value());
    const double err = std::abs(s.solution->frequencies()[0] - examples::PendulumFrequency(1.5));
    EXPECT_LT(err, previous / 50) << "N = " << N;
    previous = err;
  }
}

// Limit cycles against the published periods (../shared/ref/periodic.json).
TEST(Accuracy, VanDerPolPeriods) {
  {
    const examples::ExampleSetup e = examples::BuildExample("vanderpol", {{"eps", 1.0}});
    const HarmonicBalanceSummary s = Solve(e, 40);
    ASSERT_TRUE(s.converged()) << s.FullReport();
    EXPECT_NEAR(2 * M_PI / s.solution->frequencies()[0], 6.6632868593231301897, 1e-12);
    EXPECT_NEAR(s.solution->Amplitude(0), 2.0086198608748431365, 1e-12);
  }
  {
    const examples::ExampleSetup e = examples::BuildExample("vanderpol", {{"eps", 10.0}});
    const HarmonicBalanceSummary s = Solve(e, 340);
    ASSERT_TRUE(s.converged()) << s.FullReport();
    EXPECT_NEAR(2 * M_PI / s.solution->frequencies()[0], 19.07836956693901407, 1e-10);
  }
}

TEST(Examples, BadInputIsRefusedWithAClearMessage) {
  EXPECT_THROW(examples::BuildExample("pendulim"), std::invalid_argument);
  EXPECT_THROW(examples::BuildExample("pendulum", {{"theta", 1.0}}), std::invalid_argument);
  EXPECT_THROW(examples::BuildExample("pendulum", {{"theta0", 4.0}}), std::invalid_argument);
  EXPECT_THROW(examples::BuildExample("pendulum", {{"theta0", NAN}}), std::invalid_argument);
  EXPECT_THROW(examples::BuildExample("relativistic", {{"beta", 1.0}}), std::invalid_argument);
  EXPECT_THROW(examples::BuildExample("duffing", {{"w", -1.0}}), std::invalid_argument);
  try {
    examples::BuildExample("pendulum", {{"theta", 1.0}});
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("theta0"), std::string::npos);  // lists the parameters
  }
}

}  // namespace
}  // namespace rmhb

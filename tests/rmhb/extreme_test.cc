// Hard cases against exact references: the pendulum near its separatrix,
// the relativistic oscillator near the speed of light; automatic order
// selection (HarmonicBalanceOptions::tolerance) and the condition estimate.
// Van der Pol relaxation needs CVODE references: tests/examples.

#include <gtest/gtest.h>

#include <cmath>

#include "examples/example_system.h"
#include "examples/references.h"
#include "rmhb/harmonic_balance.h"

namespace rmhb {
namespace {

HarmonicBalanceSummary SolveToTolerance(const examples::ExampleSetup& e, int order, double tolerance = 0) {
  HarmonicBalanceOptions o;
  o.order = order;
  o.tolerance = tolerance;
  return SolveHarmonicBalance(e.problem, e.guess, o);
}

double FrequencyError(const examples::ExampleSetup& e, const HarmonicBalanceSummary& s) {
  return std::abs(s.solution->frequencies()[0] - e.reference.frequency);
}

double AmplitudeError(const examples::ExampleSetup& e, const HarmonicBalanceSummary& s) {
  const HarmonicSolution& sol = *s.solution;
  return std::abs(sol.Amplitude(sol.IndexOf(e.reference.amplitude_variable)) - e.reference.amplitude);
}

// The nome q of the exact series grows towards 1 at the separatrix (q = 0.56
// at theta0 = 3.14): the harmonics decay slowly and the Jacobian is ill
// conditioned, but N ~ 130 still reaches 1e-12 in the frequency.
TEST(Extreme, PendulumNearTheSeparatrix) {
  struct Case {
    double theta0;
    int order;
  };
  for (const Case& c : {Case{3.0, 60}, Case{3.1, 80}, Case{3.14, 128}}) {
    const examples::ExampleSetup e = examples::BuildExample("pendulum", {{"theta0", c.theta0}});
    const HarmonicBalanceSummary s = SolveToTolerance(e, c.order);
    ASSERT_TRUE(s.converged()) << c.theta0 << "\n" << s.FullReport();
    EXPECT_LT(FrequencyError(e, s), 1e-10) << "theta0 = " << c.theta0;
    EXPECT_LT(AmplitudeError(e, s), 1e-10) << "theta0 = " << c.theta0;
    // And truncation shows: the order matters, the test can fail.
    const HarmonicBalanceSummary coarse = SolveToTolerance(e, c.order / 2);
    if (coarse.converged()) {
      EXPECT_GT(FrequencyError(e, coarse), 1e-9) << "theta0 = " << c.theta0;
    }
  }
}

// beta = 0.99: v = x' saturates near +-1 and u = sqrt(1 - v^2) dips to 0.14.
TEST(Extreme, RelativisticNearTheSpeedOfLight) {
  struct Case {
    double beta;
    int order;
  };
  for (const Case& c : {Case{0.95, 110}, Case{0.99, 300}}) {
    const examples::ExampleSetup e = examples::BuildExample("relativistic", {{"beta", c.beta}});
    const HarmonicBalanceSummary s = SolveToTolerance(e, c.order);
    ASSERT_TRUE(s.converged()) << c.beta << "\n" << s.FullReport();
    EXPECT_LT(FrequencyError(e, s), 1e-10) << "beta = " << c.beta;
    EXPECT_LT(AmplitudeError(e, s), 1e-10) << "beta = " << c.beta;
  }
}

// --tol: the chosen order meets the tolerance against the exact reference,
// and the estimate is honest: never below the true error.
TEST(OrderSelection, ChosenOrderMeetsTheToleranceAndTheEstimateIsHonest) {
  struct Case {
    const char* name;
    const char* parameter;
    double value;
    double tolerance;
  };
  for (const Case& c : {Case{"pendulum", "theta0", 1.5, 1e-8}, Case{"pendulum", "theta0", 3.1, 1e-10},
                        Case{"relativistic", "beta", 0.85, 1e-10},
                        Case{"relativistic", "beta", 0.95, 1e-12}}) {
    const examples::ExampleSetup e = examples::BuildExample(c.name, {{c.parameter, c.value}});
    const HarmonicBalanceSummary s = SolveToTolerance(e, 10, c.tolerance);
    ASSERT_TRUE(s.converged()) << c.name << " " << c.value << "\n" << s.FullReport();
    const double error = std::max(FrequencyError(e, s) / e.reference.frequency, AmplitudeError(e, s));
    EXPECT_LE(error, c.tolerance) << c.name << " " << c.value << " at N = " << s.order;
    EXPECT_LE(s.truncation_estimate, c.tolerance);
    EXPECT_GE(s.truncation_estimate, error) << c.name << " " << c.value;
    ASSERT_GE(s.orders_tried.size(), 2u);
    EXPECT_EQ(s.orders_tried.back(), s.order);
    // The last step still changed the solution by a tenth of the estimate
    // or more: the selection does not run far past the tolerance.
    const HarmonicBalanceSummary before = SolveToTolerance(e, s.orders_tried[s.orders_tried.size() - 2]);
    ASSERT_TRUE(before.converged());
    EXPECT_GE(SolutionDifference(*before.solution, *s.solution), 0.1 * s.truncation_estimate);
  }
}

TEST(OrderSelection, UnreachableToleranceIsNotConvergedWithTheEstimate) {
  const examples::ExampleSetup e = examples::BuildExample("pendulum", {{"theta0", 3.1}});
  HarmonicBalanceOptions o;
  o.order = 10;
  o.tolerance = 1e-12;
  o.max_order = 40;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(e.problem, e.guess, o);
  EXPECT_EQ(s.solver.status, SolverStatus::kNoConvergence);
  EXPECT_NE(s.solver.message.find("not reached by max_order 40"), std::string::npos) << s.solver.message;
  EXPECT_GT(s.truncation_estimate, 1e-12);
  EXPECT_EQ(s.order, 40);
}

// From order 1 (forced Duffing, no exact solution): the selected solution is
// within the tolerance of a high-order one.
TEST(OrderSelection, StartsFromOrderOne) {
  const examples::ExampleSetup e = examples::BuildExample("duffing");
  const HarmonicBalanceSummary s = SolveToTolerance(e, 1, 1e-10);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  const HarmonicBalanceSummary high = SolveToTolerance(e, 60);
  ASSERT_TRUE(high.converged());
  EXPECT_LE(SolutionDifference(*s.solution, *high.solution), 1e-10) << "N = " << s.order;
  EXPECT_GE(s.truncation_estimate, SolutionDifference(*s.solution, *high.solution));
}

TEST(OrderSelection, BadToleranceIsRefused) {
  const examples::ExampleSetup e = examples::BuildExample("pendulum");
  for (double tol : {-1e-10, double(NAN), double(INFINITY)}) {
    HarmonicBalanceOptions o;
    o.tolerance = tol;
    EXPECT_THROW(SolveHarmonicBalance(e.problem, e.guess, o), std::invalid_argument) << tol;
  }
}

// The cheap estimates against the SVD's exact 2-norm condition: the LU's
// 1-norm estimate (Hager/Higham, square Van der Pol) and min/max |R_ii| of the
// QR (overdetermined pendulum) are within a factor ~n of it, and both see
// the conditioning worsen towards the hard cases.
TEST(ConditionEstimate, MatchesTheSvdAndWorsensForTheHardCases) {
  struct Case {
    const char* name;
    const char* parameter;
    double value;
    int order;
  };
  const Case cases[] = {{"vanderpol", "eps", 1.0, 40}, {"vanderpol", "eps", 5.0, 120},
                        {"pendulum", "theta0", 1.5, 40}, {"pendulum", "theta0", 3.1, 40}};
  double easier = 1;
  for (const Case& c : cases) {
    const examples::ExampleSetup e = examples::BuildExample(c.name, {{c.parameter, c.value}});
    HarmonicBalanceOptions o;
    o.order = c.order;
    o.solver.estimate_condition = true;
    const HarmonicBalanceSummary s = SolveHarmonicBalance(e.problem, e.guess, o);
    ASSERT_TRUE(s.converged()) << s.FullReport();
    const double rcond = s.solver.reciprocal_condition, exact = 1 / s.solver.condition_estimate;
    const double n = s.solver.num_unknowns;
    EXPECT_GT(rcond, exact / (10 * n)) << c.name << " " << c.value;
    EXPECT_LT(rcond, exact * 10 * n) << c.name << " " << c.value;
    if (&c - cases == 1 || &c - cases == 3) {  // the harder of each pair
      EXPECT_LT(rcond, easier) << c.name << " " << c.value;
    }
    easier = rcond;
  }
}

}  // namespace
}  // namespace rmhb

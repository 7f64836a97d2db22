#include "integrators/ida_integrator.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "integrators/cvode_integrator.h"
#include "test_systems.h"

namespace rmhb::integrators {
namespace {

using ::testing::HasSubstr;
using testing::kNaN;
using testing::Vec;
using testing::Grid;

// Semi-explicit index 1:  x' = -x + z,  0 = z - x^2.  From x(0) = 1/2 the
// solution is x = 1 / (1 + e^t), z = x^2.
DaeSystem Logistic() {
  DaeSystem system;
  system.dimension = 2;
  system.residual = [](double, const double* y, const double* yp, double* r) {
    r[0] = yp[0] - (-y[0] + y[1]);
    r[1] = y[1] - y[0] * y[0];
  };
  system.differential = {true, false};
  return system;
}

double MaxLogisticError(const Trajectory& trajectory) {
  double error = 0;
  for (int k = 0; k < trajectory.size(); ++k) {
    const double x = 1.0 / (1.0 + std::exp(trajectory.times[k]));
    error = std::max(error, std::fabs(trajectory.states(k, 0) - x));
    error = std::max(error, std::fabs(trajectory.states(k, 1) - x * x));
  }
  return error;
}

TEST(IntegrateDae, SemiExplicitIndexOneMatchesExactSolution) {
  IntegratorOptions options;
  options.compute_consistent_initial_condition = false;  // Already consistent.
  const IntegrationResult result =
      IntegrateDae(Logistic(), Vec({0.5, 0.25}), Vec({-0.25, 0.0}), 0.0, Grid(0, 5, 11), options);
  ASSERT_TRUE(result.ok()) << result.BriefReport();
  EXPECT_EQ(result.solver, "IDA/BDF");
  const double error = MaxLogisticError(result.trajectory);
  RecordProperty("max_error", testing::Sci(error));
  EXPECT_LT(error, 1e-10);
  EXPECT_GT(result.rhs_evaluations, result.steps);
}

// A MEMS plate's pull-in as a DAE, the force an algebraic unknown:
// The friction block of cvode_integrator_test's crawl test as a DAE
// (x' = v, v' = f, 0 = f + 0.3 sign(v) + x - 0.6 cos 0.8t): IDA's corrector
// fails outright where the block sticks (CVODE crawls there), so the
// integration stops at once, saying where.
TEST(IntegrateDae, AFrictionBlockStoppedAtStickEndsTheIntegrationThere) {
  DaeSystem friction;
  friction.dimension = 3;
  friction.residual = [](double t, const double* y, const double* yp, double* r) {
    r[0] = yp[0] - y[1];
    r[1] = yp[1] - y[2];
    r[2] = y[2] + 0.3 * ((y[1] > 0) - (y[1] < 0)) + y[0] - 0.6 * std::cos(0.8 * t);
  };
  friction.differential = {true, true, false};
  IntegratorOptions options;
  options.relative_tolerance = 1e-11;
  options.absolute_tolerance = 1e-13;
  const IntegrationResult result = IntegrateDae(friction, Vec({0, 0, 0.6}), Vec({0, 0.6, 0}), 0.0, {10.0}, options);
  ASSERT_FALSE(result.ok());
  EXPECT_LE(result.steps, 100'000) << result.message;
  const double stopped = std::stod(result.message.substr(result.message.find("stopped at t = ") + 15));
  EXPECT_NEAR(stopped, 1.8197640, 1e-6) << result.message;  // v's first zero (cvode_integrator_test)
}

// x' = v, v' = f, 0 = f (1 - x)^2 - a. x reaches 1 at the exact time
// pi / (2 sqrt(2a)) with v and f unbounded: IDA's steps fall to the round-off
// of t there, and the integration stops with where and why instead of
// running out its step budget.
TEST(IntegrateDae, AStepStuckAtTheRoundOffOfTStopsEarly) {
  constexpr double a = 0.2;
  DaeSystem pull_in;
  pull_in.dimension = 3;
  pull_in.residual = [](double, const double* y, const double* yp, double* r) {
    r[0] = yp[0] - y[1];
    r[1] = yp[1] - y[2];
    r[2] = y[2] * (1 - y[0]) * (1 - y[0]) - a;
  };
  pull_in.differential = {true, true, false};
  const IntegrationResult result =
      IntegrateDae(pull_in, Vec({0, 0, a}), Vec({0, a, 0}), 0.0, {3.0}, IntegratorOptions{});
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result.message, HasSubstr("round-off of t"));
  EXPECT_LE(result.steps, 200'000) << result.message;
  const double T = kPi / (2 * std::sqrt(2 * a));
  const double stopped = std::stod(result.message.substr(result.message.find("at t = ") + 7));
  EXPECT_NEAR(stopped, T, 1e-6 * T) << result.message;
}

TEST(IntegrateDae, InconsistentInitialConditionIsRepaired) {
  // z0 and yp0 are wrong; only the differential x0 is trusted.
  const IntegrationResult result =
      IntegrateDae(Logistic(), Vec({0.5, 0.0}), Vec({0.0, 0.0}), 0.0, Grid(0, 5, 11));
  ASSERT_TRUE(result.ok()) << result.BriefReport();
  // The t0 output is the corrected state, not the guess.
  EXPECT_EQ(result.trajectory.states(0, 0), 0.5);
  EXPECT_NEAR(result.trajectory.states(0, 1), 0.25, 1e-14);
  const double error = MaxLogisticError(result.trajectory);
  RecordProperty("max_error", testing::Sci(error));
  EXPECT_LT(error, 1e-10);
}

// Shows that the option really switches IDACalcIC off: the same start
// that is repaired above cannot be integrated as given (IDA fails its
// first step with IDA_CONV_FAIL at t = 0).
TEST(IntegrateDae, WithoutRepairAnInconsistentStartFails) {
  IntegratorOptions options;
  options.compute_consistent_initial_condition = false;
  const IntegrationResult result =
      IntegrateDae(Logistic(), Vec({0.5, 0.0}), Vec({0.0, 0.0}), 0.0, {0.0, 5.0}, options);
  EXPECT_FALSE(result.ok());
  ASSERT_EQ(result.trajectory.size(), 1);
  EXPECT_EQ(result.trajectory.states(0, 1), 0.0);  // The t0 output echoes the input.
}

TEST(IntegrateDae, ImplicitOdeWithAllComponentsDifferential) {
  DaeSystem system;
  system.dimension = 2;
  system.residual = [](double, const double* y, const double* yp, double* r) {
    r[0] = yp[0] - y[1];
    r[1] = yp[1] + y[0];
  };
  // differential left empty: all differential.
  IntegratorOptions options;
  options.relative_tolerance = 1e-11;
  options.absolute_tolerance = 1e-13;
  const IntegrationResult result =
      IntegrateDae(system, Vec({1, 0}), Vec({0, -1}), 0.0, Grid(0, 10, 21), options);
  ASSERT_TRUE(result.ok()) << result.BriefReport();
  double error = 0;
  for (int k = 0; k < result.trajectory.size(); ++k) {
    error = std::max(
        error, std::fabs(result.trajectory.states(k, 0) - std::cos(result.trajectory.times[k])));
  }
  RecordProperty("max_error", testing::Sci(error));
  EXPECT_LT(error, 1e-8);
}

// Pendulum in Cartesian coordinates, index-1 form (constraint differentiated
// twice, tension lambda algebraic). Must agree with the angle form
// theta'' = -sin(theta) integrated by CVODE.
TEST(IntegrateDae, CartesianPendulumAgreesWithAngleForm) {
  constexpr double kTheta0 = testing::kPendulumTheta0;
  DaeSystem system;
  system.dimension = 5;  // x, y, u, v, lambda
  system.residual = [](double, const double* s, const double* sp, double* r) {
    const double x = s[0], y = s[1], u = s[2], v = s[3], lambda = s[4];
    r[0] = sp[0] - u;
    r[1] = sp[1] - v;
    r[2] = sp[2] + lambda * x;
    r[3] = sp[3] + lambda * y + 1.0;
    r[4] = u * u + v * v - lambda * (x * x + y * y) - y;
  };
  system.differential = {true, true, true, true, false};
  // Positions exact, tension and all derivatives left for IDACalcIC.
  const Eigen::VectorXd s0 = Vec({std::sin(kTheta0), -std::cos(kTheta0), 0, 0, 0});
  IntegratorOptions options;
  options.relative_tolerance = 1e-11;
  options.absolute_tolerance = 1e-13;
  const std::vector<double> times = Grid(0, 10, 41);
  const IntegrationResult dae =
      IntegrateDae(system, s0, Eigen::VectorXd::Zero(5), 0.0, times, options);
  ASSERT_TRUE(dae.ok()) << dae.BriefReport();
  const IntegrationResult ode = IntegrateOde(testing::Pendulum(), Vec({kTheta0, 0}), 0.0, times);
  ASSERT_TRUE(ode.ok()) << ode.BriefReport();

  double error = 0, drift = 0;
  for (int k = 0; k < dae.trajectory.size(); ++k) {
    const double theta = ode.trajectory.states(k, 0);
    const Eigen::RowVectorXd s = dae.trajectory.states.row(k);
    error = std::max({error, std::fabs(s[0] - std::sin(theta)), std::fabs(s[1] + std::cos(theta))});
    drift = std::max(drift, std::fabs(s[0] * s[0] + s[1] * s[1] - 1.0));
  }
  RecordProperty("max_error", testing::Sci(error));
  RecordProperty("constraint_drift", testing::Sci(drift));
  EXPECT_NEAR(dae.trajectory.states(0, 4), std::cos(kTheta0), 1e-12);  // Repaired tension.
  EXPECT_LT(error, 1e-7);
  // Index reduction loses the position constraint; it may drift, slowly.
  EXPECT_LT(drift, 1e-7);
}

TEST(IntegrateDae, NanFromResidualEndsInFailure) {
  DaeSystem system = Logistic();
  system.residual = [](double t, const double* y, const double* yp, double* r) {
    r[0] = yp[0] - (-y[0] + y[1]);
    r[1] = t > 1.0 ? kNaN : y[1] - y[0] * y[0];
  };
  ::testing::internal::CaptureStderr();
  const IntegrationResult result =
      IntegrateDae(system, Vec({0.5, 0.25}), Vec({-0.25, 0}), 0.0, {0.5, 1.0, 2.0, 3.0});
  const std::string console = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(result.status, IntegrationStatus::kFailure);
  EXPECT_THAT(result.message, HasSubstr("IDA_"));
  EXPECT_THAT(result.message,
              HasSubstr("residual returned a non-finite value (nan) in component 1"));
  EXPECT_TRUE(result.trajectory.states.allFinite());
  EXPECT_LE(result.trajectory.size(), 2);
  EXPECT_TRUE(console.empty()) << console;
}

TEST(IntegrateDae, UnsolvableAlgebraicEquationFailsInInitialCondition) {
  DaeSystem system;
  system.dimension = 2;
  system.residual = [](double, const double* y, const double* yp, double* r) {
    r[0] = yp[0] + y[0];
    r[1] = y[1] * y[1] + 1.0;  // No real root.
  };
  system.differential = {true, false};
  const IntegrationResult result = IntegrateDae(system, Vec({1, 0.5}), Vec({-1, 0}), 0.0, {1.0});
  EXPECT_FALSE(result.ok());
  EXPECT_THAT(result.message, HasSubstr("IDACalcIC"));
  EXPECT_EQ(result.trajectory.size(), 0);
}

TEST(IntegrateDae, MisuseThrowsInvalidArgument) {
  const DaeSystem good = Logistic();
  const Eigen::VectorXd y0 = Vec({0.5, 0.25}), yp0 = Vec({-0.25, 0});
  DaeSystem bad_id = good;
  bad_id.differential = {true};
  DaeSystem no_residual = good;
  no_residual.residual = nullptr;
  DaeSystem zero_dimension = good;
  zero_dimension.dimension = 0;
  zero_dimension.differential.clear();
  EXPECT_THROW(IntegrateDae(bad_id, y0, yp0, 0, {1.0}), std::invalid_argument);
  EXPECT_THROW(IntegrateDae(no_residual, y0, yp0, 0, {1.0}), std::invalid_argument);
  EXPECT_THROW(IntegrateDae(zero_dimension, Eigen::VectorXd(), Eigen::VectorXd(), 0, {1.0}),
               std::invalid_argument);
  EXPECT_THROW(IntegrateDae(good, y0, Vec({0}), 0, {1.0}), std::invalid_argument);
  EXPECT_THROW(IntegrateDae(good, y0, Vec({kNaN, 0}), 0, {1.0}), std::invalid_argument);
  EXPECT_THROW(IntegrateDae(good, Vec({kNaN, 0}), yp0, 0, {1.0}), std::invalid_argument);
  EXPECT_THROW(IntegrateDae(good, y0, yp0, 0, {1.0, 0.5}), std::invalid_argument);
  IntegratorOptions options;
  options.max_order = 6;  // IDA is BDF: at most 5, whatever method says.
  EXPECT_THROW(IntegrateDae(good, y0, yp0, 0, {1.0}, options), std::invalid_argument);
  options = IntegratorOptions();
  options.absolute_tolerance = -1;
  EXPECT_THROW(IntegrateDae(good, y0, yp0, 0, {1.0}, options), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb::integrators

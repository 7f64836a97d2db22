#include "integrators/event_detection.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <vector>

#include "test_systems.h"

namespace rmhb::integrators {
namespace {

using ::testing::HasSubstr;
using testing::kPi;
using testing::Vec;
using testing::kPendulumPeriod;
using testing::kPendulumTheta0;

double Velocity(double, const double* y) { return y[1]; }
double Position(double, const double* y) { return y[0]; }

// The period measurement the harmonic-balance validation relies on:
// theta' crosses zero upward once per period (at theta = -theta0).
TEST(FindCrossings, PendulumPeriodToElevenDigits) {
  IntegratorOptions options;
  options.relative_tolerance = 1e-14;
  options.absolute_tolerance = 1e-16;
  IntegrationResult info;
  const std::vector<double> crossings =
      FindCrossings(testing::Pendulum(), Vec({kPendulumTheta0, 0.0}), 0.0, 2.6 * kPendulumPeriod,
                    Velocity, +1, options, &info);
  ASSERT_TRUE(info.ok()) << info.BriefReport();
  ASSERT_EQ(crossings.size(), 3u);  // T/2, 3T/2, 5T/2.

  const double period = crossings[1] - crossings[0];
  const double relative_error = std::fabs(period - kPendulumPeriod) / kPendulumPeriod;
  const double half_period_error = std::fabs(crossings[0] - kPendulumPeriod / 2) / kPendulumPeriod;
  const double two_period_error =
      std::fabs((crossings[2] - crossings[0]) / 2 - kPendulumPeriod) / kPendulumPeriod;
  RecordProperty("period_relative_error", testing::Sci(relative_error));
  RecordProperty("half_period_relative_error", testing::Sci(half_period_error));
  RecordProperty("seconds", testing::Sci(info.seconds));
  std::printf(
      "pendulum period %.17g, relative error %.2e (T/2: %.2e, 2T: %.2e), %ld steps, %.2g s\n",
      period, relative_error, half_period_error, two_period_error, info.steps, info.seconds);
  EXPECT_LT(relative_error, 1e-11);
  EXPECT_LT(half_period_error, 1e-11);
  EXPECT_LT(two_period_error, 1e-11);

  // The reported states are the crossing points: theta = -theta0, at rest.
  ASSERT_EQ(info.trajectory.size(), 3);
  EXPECT_EQ(info.trajectory.times, crossings);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(info.trajectory.states(k, 0), -kPendulumTheta0, 1e-11);
    EXPECT_NEAR(info.trajectory.states(k, 1), 0.0, 1e-14);
  }
}

TEST(FindCrossings, DefaultTolerancesStillGiveTenDigitPeriod) {
  const std::vector<double> crossings = FindCrossings(
      testing::Pendulum(), Vec({kPendulumTheta0, 0.0}), 0.0, 1.6 * kPendulumPeriod, Velocity, +1);
  ASSERT_EQ(crossings.size(), 2u);
  EXPECT_NEAR((crossings[1] - crossings[0]) / kPendulumPeriod, 1.0, 1e-10);
}

// x = cos t vanishes at pi/2 + k pi: downward for even k, upward for odd.
// The exact solution checks the root times; the state reported at each root
// checks the secant polish, since CVODE's bracket alone leaves |x| up to
// ~1e-13 there at this tolerance (measured), the polished root ~3e-16.
TEST(FindCrossings, OscillatorRootsInEachDirection) {
  IntegratorOptions options;
  options.relative_tolerance = 1e-13;
  options.absolute_tolerance = 1e-15;
  const OdeSystem system = testing::HarmonicOscillator();
  const Eigen::VectorXd y0 = Vec({1.0, 0.0});
  const double t_end = 10.0;

  IntegrationResult info;
  const std::vector<double> both =
      FindCrossings(system, y0, 0.0, t_end, Position, 0, options, &info);
  const std::vector<double> down = FindCrossings(system, y0, 0.0, t_end, Position, -1, options);
  const std::vector<double> up = FindCrossings(system, y0, 0.0, t_end, Position, +1, options);
  ASSERT_EQ(both.size(), 3u);  // pi/2, 3pi/2, 5pi/2
  ASSERT_EQ(down.size(), 2u);
  ASSERT_EQ(up.size(), 1u);
  double error = 0;
  for (std::size_t k = 0; k < both.size(); ++k) {
    error = std::max(error, std::fabs(both[k] - (0.5 + k) * kPi));
  }
  RecordProperty("max_root_error", testing::Sci(error));
  EXPECT_LT(error, 2e-12);  // Trajectory accuracy; measured 7.5e-13.
  ASSERT_EQ(info.trajectory.size(), 3);
  EXPECT_LT(info.trajectory.Component(0).cwiseAbs().maxCoeff(), 2e-15);
  EXPECT_DOUBLE_EQ(down[0], both[0]);
  EXPECT_DOUBLE_EQ(down[1], both[2]);
  EXPECT_DOUBLE_EQ(up[0], both[1]);
}

TEST(FindCrossings, ZeroAtInitialTimeIsNotACrossing) {
  // theta' = 0 at t0 by construction; the first upward crossing is at T/2.
  const std::vector<double> crossings =
      FindCrossings(testing::Pendulum(), Vec({kPendulumTheta0, 0.0}), 0.0, 1.0, Velocity, 0);
  EXPECT_TRUE(crossings.empty());
}

TEST(FindCrossings, NoCrossingIsAnEmptySuccess) {
  IntegrationResult info;
  const std::vector<double> crossings = FindCrossings(
      testing::HarmonicOscillator(), Vec({1.0, 0.0}), 0.0, 10.0,
      [](double, const double* y) { return y[0] + 2.0; }, 0, {}, &info);
  EXPECT_TRUE(crossings.empty());
  EXPECT_TRUE(info.ok()) << info.BriefReport();
  EXPECT_EQ(info.trajectory.size(), 0);
  EXPECT_GT(info.steps, 0);
}

TEST(FindCrossings, NonFiniteEventFunctionIsAFailure) {
  IntegrationResult info;
  const std::vector<double> crossings = FindCrossings(
      testing::HarmonicOscillator(), Vec({1.0, 0.0}), 0.0, 10.0,
      [](double t, const double* y) {
        return t > 2.0 ? std::numeric_limits<double>::infinity() : y[0];
      },
      0, {}, &info);
  EXPECT_EQ(info.status, IntegrationStatus::kFailure);
  EXPECT_THAT(info.message, HasSubstr("CV_RTFUNC_FAIL"));
  EXPECT_THAT(info.message, HasSubstr("event function returned a non-finite value"));
  // The crossing at pi/2 precedes the failure and is kept.
  ASSERT_EQ(crossings.size(), 1u);
  EXPECT_NEAR(crossings[0], kPi / 2, 1e-10);
}

TEST(FindCrossings, MisuseThrowsInvalidArgument) {
  const OdeSystem system = testing::HarmonicOscillator();
  const Eigen::VectorXd y0 = Vec({1.0, 0.0});
  EXPECT_THROW(FindCrossings(system, y0, 0.0, 1.0, Position, 2), std::invalid_argument);
  EXPECT_THROW(FindCrossings(system, y0, 0.0, 0.0, Position, 0), std::invalid_argument);
  EXPECT_THROW(FindCrossings(system, y0, 0.0, -1.0, Position, 0), std::invalid_argument);
  EXPECT_THROW(FindCrossings(system, y0, 0.0, 1.0, EventFunction(), 0), std::invalid_argument);
  EXPECT_THROW(FindCrossings(system, Vec({1.0}), 0.0, 1.0, Position, 0), std::invalid_argument);
  EXPECT_THROW(FindCrossings(system, Vec({NAN, 0.0}), 0.0, 1.0, Position, 0),
               std::invalid_argument);
}

}  // namespace
}  // namespace rmhb::integrators

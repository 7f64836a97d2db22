#include "integrators/cvode_integrator.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "test_systems.h"

namespace rmhb::integrators {
namespace {

using testing::HarmonicOscillator;
using ::testing::HasSubstr;
using testing::kNaN;
using testing::kPi;
using testing::Vec;
using testing::Grid;
using Method = IntegratorOptions::Method;

double MaxOscillatorError(const Trajectory& trajectory) {
  double error = 0;
  for (int k = 0; k < trajectory.size(); ++k) {
    const double t = trajectory.times[k];
    error = std::max(error, std::fabs(trajectory.states(k, 0) - std::cos(t)));
    error = std::max(error, std::fabs(trajectory.states(k, 1) + std::sin(t)));
  }
  return error;
}

TEST(IntegrateOde, HarmonicOscillatorMatchesCosineWithAdams) {
  const std::vector<double> times = Grid(0.0, 20.0, 81);
  const IntegrationResult result = IntegrateOde(HarmonicOscillator(), Vec({1, 0}), 0.0, times);
  ASSERT_TRUE(result.ok()) << result.BriefReport();
  ASSERT_EQ(result.trajectory.size(), 81);
  EXPECT_EQ(result.trajectory.times, times);
  const double error = MaxOscillatorError(result.trajectory);
  RecordProperty("max_error", testing::Sci(error));
  // Default rtol 1e-12 over ~3 periods: the global error is a few hundred
  // times the local tolerance (measured 5.2e-10).
  EXPECT_LT(error, 1e-9);
  EXPECT_EQ(result.solver, "CVODE/Adams");
  EXPECT_GT(result.steps, 0);
  EXPECT_GE(result.rhs_evaluations, result.steps);
  EXPECT_GE(result.seconds, 0.0);
  EXPECT_TRUE(result.message.empty());
}

TEST(IntegrateOde, HarmonicOscillatorMatchesCosineWithBdf) {
  IntegratorOptions options;
  options.method = Method::kBdf;
  options.relative_tolerance = 1e-10;
  options.absolute_tolerance = 1e-12;
  const IntegrationResult result =
      IntegrateOde(HarmonicOscillator(), Vec({1, 0}), 0.0, Grid(0.0, 10.0, 21), options);
  ASSERT_TRUE(result.ok()) << result.BriefReport();
  EXPECT_EQ(result.solver, "CVODE/BDF");
  // BDF (order <= 5) is far less accurate per step than Adams; the bound
  // still catches a wrong solution by many orders of magnitude.
  EXPECT_LT(MaxOscillatorError(result.trajectory), 1e-7);
}

TEST(IntegrateOde, OutputAtInitialTimeIsInitialStateBitForBit) {
  // 0.1 is not representable: a round trip through any arithmetic would show.
  const Eigen::VectorXd y0 = Vec({0.1, -1.0 / 3.0});
  const IntegrationResult result = IntegrateOde(HarmonicOscillator(), y0, 2.5, {2.5, 3.0});
  ASSERT_TRUE(result.ok()) << result.BriefReport();
  EXPECT_EQ(result.trajectory.states(0, 0), y0[0]);
  EXPECT_EQ(result.trajectory.states(0, 1), y0[1]);
  EXPECT_NE(result.trajectory.states(1, 0), y0[0]);
}

TEST(IntegrateOde, ExponentialDecayMatchesExactSolution) {
  const Eigen::VectorXd rates = Vec({0.1, 1.0, 3.0, 10.0});
  OdeSystem system;
  system.dimension = 4;
  system.rhs = [&rates](double, const double* y, double* ydot) {
    for (int i = 0; i < 4; ++i) ydot[i] = -rates[i] * y[i];
  };
  const Eigen::VectorXd y0 = Vec({1.0, 2.0, -3.0, 4.0});
  const IntegrationResult result = IntegrateOde(system, y0, 1.0, Grid(1.5, 3.0, 4));
  ASSERT_TRUE(result.ok()) << result.BriefReport();
  double worst = 0;
  for (int k = 0; k < result.trajectory.size(); ++k) {
    for (int i = 0; i < 4; ++i) {
      const double exact = y0[i] * std::exp(-rates[i] * (result.trajectory.times[k] - 1.0));
      // Absolute tolerance dominates once the fast mode has decayed.
      worst = std::max(
          worst, std::fabs(result.trajectory.states(k, i) - exact) / (std::fabs(exact) + 1e-2));
    }
  }
  RecordProperty("max_scaled_error", testing::Sci(worst));
  EXPECT_LT(worst, 1e-10);
}

// Prothero-Robinson: y' = lambda (y - sin t) + cos t, exact y = sin t. With
// lambda = -1e6 Adams would be stability-limited to h ~ 1e-6 (~1e7 steps);
// BDF must follow the smooth solution in a few hundred.
TEST(IntegrateOde, StiffProtheroRobinsonWithBdfIsAccurateInFewSteps) {
  constexpr double kLambda = -1e6;
  OdeSystem system;
  system.dimension = 1;
  system.rhs = [](double t, const double* y, double* ydot) {
    ydot[0] = kLambda * (y[0] - std::sin(t)) + std::cos(t);
  };
  IntegratorOptions options;
  options.method = Method::kBdf;
  options.relative_tolerance = 1e-10;
  options.absolute_tolerance = 1e-12;
  const IntegrationResult result = IntegrateOde(system, Vec({0.0}), 0.0, Grid(0, 10, 11), options);
  ASSERT_TRUE(result.ok()) << result.BriefReport();
  double error = 0;
  for (int k = 0; k < result.trajectory.size(); ++k) {
    error = std::max(
        error, std::fabs(result.trajectory.states(k, 0) - std::sin(result.trajectory.times[k])));
  }
  RecordProperty("max_error", testing::Sci(error));
  RecordProperty("steps", std::to_string(result.steps));
  EXPECT_LT(error, 1e-9);
  EXPECT_LT(result.steps, 5000);
}

// Van der Pol, mu = 1000: relaxation oscillation with period ~1614 and
// boundary layers of width ~1/mu. No closed form, so check that BDF gets
// through a full cycle in bounded work and stays on the cycle (|x| <= ~2).
TEST(IntegrateOde, StiffVanDerPolWithBdfSucceedsInBoundedSteps) {
  constexpr double kMu = 1000.0;
  OdeSystem system;
  system.dimension = 2;
  system.rhs = [](double, const double* y, double* ydot) {
    ydot[0] = y[1];
    ydot[1] = kMu * (1.0 - y[0] * y[0]) * y[1] - y[0];
  };
  IntegratorOptions options;
  options.method = Method::kBdf;
  options.relative_tolerance = 1e-8;
  options.absolute_tolerance = 1e-10;
  const IntegrationResult result =
      IntegrateOde(system, Vec({2.0, 0.0}), 0.0, Grid(0.0, 2000.0, 401), options);
  ASSERT_TRUE(result.ok()) << result.BriefReport();
  RecordProperty("steps", std::to_string(result.steps));
  EXPECT_LT(result.steps, 20000);
  const Eigen::VectorXd x = result.trajectory.Component(0);
  EXPECT_LT(x.cwiseAbs().maxCoeff(), 2.05);
  // One full relaxation cycle: x has gone from +2 to about -2 and back.
  EXPECT_LT(x.minCoeff(), -1.9);
  EXPECT_GT(x.tail(1)[0], 1.0);
}

TEST(IntegrateOde, RobertsonWithBdfConservesMassOverElevenDecades) {
  OdeSystem system;
  system.dimension = 3;
  system.rhs = [](double, const double* y, double* ydot) {
    ydot[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
    ydot[2] = 3e7 * y[1] * y[1];
    ydot[1] = -ydot[0] - ydot[2];
  };
  IntegratorOptions options;
  options.method = Method::kBdf;
  options.relative_tolerance = 1e-10;
  options.absolute_tolerance = 1e-16;
  std::vector<double> times;
  for (double t = 0.4; t < 5e10; t *= 10) times.push_back(t);
  const IntegrationResult result = IntegrateOde(system, Vec({1, 0, 0}), 0.0, times, options);
  ASSERT_TRUE(result.ok()) << result.BriefReport();
  RecordProperty("steps", std::to_string(result.steps));
  // Measured 3873; Adams would be stability-bound to h ~ 1e-4 at late times.
  EXPECT_LT(result.steps, 10000);
  for (int k = 0; k < result.trajectory.size(); ++k) {
    const Eigen::RowVectorXd y = result.trajectory.states.row(k);
    // Linear invariants are preserved by BDF up to the Newton tolerance.
    EXPECT_NEAR(y.sum(), 1.0, 1e-12) << "t = " << result.trajectory.times[k];
    EXPECT_GT(y.minCoeff(), -1e-14) << "t = " << result.trajectory.times[k];
  }
  // Classic checkpoint (SUNDIALS cvRoberts_dns, Hairer-Wanner): at t = 40,
  // y1 = 0.7158271, y3 = 0.2841729 to the digits printed there.
  EXPECT_NEAR(result.trajectory.states(2, 0), 0.7158271, 1e-7);
  EXPECT_NEAR(result.trajectory.states(2, 1), 9.185535e-6, 1e-12);
}

TEST(IntegrateOde, TightestRecommendedToleranceRunsAndIsMoreAccurate) {
  IntegratorOptions options;
  options.relative_tolerance = kTightestRelativeTolerance;
  options.absolute_tolerance = 1e-20;
  const std::vector<double> times = {2 * kPi, 4 * kPi};
  const IntegrationResult tight =
      IntegrateOde(HarmonicOscillator(), Vec({1, 0}), 0.0, times, options);
  const IntegrationResult standard = IntegrateOde(HarmonicOscillator(), Vec({1, 0}), 0.0, times);
  ASSERT_TRUE(tight.ok()) << tight.BriefReport();
  ASSERT_TRUE(standard.ok()) << standard.BriefReport();
  const double error = MaxOscillatorError(tight.trajectory);
  RecordProperty("max_error", testing::Sci(error));
  EXPECT_LT(error, 5e-13);
  EXPECT_LT(100 * error, MaxOscillatorError(standard.trajectory));
}

TEST(IntegrateOde, ToleranceBelowRoundOffIsAFailureNotAnException) {
  IntegratorOptions options;
  options.relative_tolerance = 1e-17;
  options.absolute_tolerance = 1e-20;
  IntegrationResult result;
  ASSERT_NO_THROW(result = IntegrateOde(HarmonicOscillator(), Vec({1, 0}), 0.0, {1.0}, options));
  EXPECT_FALSE(result.ok());
  EXPECT_THAT(result.message, HasSubstr("CV_TOO_MUCH_ACC"));
  EXPECT_EQ(result.trajectory.size(), 0);
}

// ---- Failures of the model are statuses, never hangs or crashes -------------

OdeSystem NanAfter(double t_bad) {
  OdeSystem system = HarmonicOscillator();
  system.rhs = [t_bad](double t, const double* y, double* ydot) {
    ydot[0] = y[1];
    ydot[1] = t > t_bad ? kNaN : -y[0];
  };
  return system;
}

// The flag differs by corrector: CVODE 6.4's fixed-point solver (Adams)
// reports any failed function evaluation as non-convergence, so the step
// is retried and the run ends in CV_CONV_FAILURE; Newton (BDF) passes the
// unrecoverable rhs failure through. The message names the cause either way.
void ExpectCleanNanFailure(Method method, const char* flag) {
  IntegratorOptions options;
  options.method = method;
  ::testing::internal::CaptureStderr();
  const IntegrationResult result =
      IntegrateOde(NanAfter(1.0), Vec({1, 0}), 0.0, {0.5, 1.0, 1.5, 2.0}, options);
  const std::string console = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(result.status, IntegrationStatus::kFailure);
  EXPECT_THAT(result.message, HasSubstr(flag));
  EXPECT_THAT(result.message, HasSubstr("rhs returned a non-finite value (nan) in component 1"));
  // A handful of retries, not a creep towards t = 1 with ever smaller steps.
  EXPECT_LT(result.rhs_evaluations, 1000);
  // Outputs before the NaN region are kept, and none of them is poisoned.
  EXPECT_GE(result.trajectory.size(), 1);
  EXPECT_LE(result.trajectory.size(), 2);
  EXPECT_TRUE(result.trajectory.states.allFinite());
  EXPECT_EQ(result.trajectory.states.rows(), result.trajectory.size());
  EXPECT_LT(result.seconds, 1.0);
  EXPECT_TRUE(console.empty()) << "SUNDIALS wrote to stderr: " << console;
}

TEST(IntegrateOde, NanFromRhsEndsInFailureWithAdams) {
  ExpectCleanNanFailure(Method::kAdams, "CV_CONV_FAILURE");
}
TEST(IntegrateOde, NanFromRhsEndsInFailureWithBdf) {
  ExpectCleanNanFailure(Method::kBdf, "CV_RHSFUNC_FAIL");
}

TEST(IntegrateOde, NanAtInitialPointFailsAtOnce) {
  const IntegrationResult result = IntegrateOde(NanAfter(-1.0), Vec({1, 0}), 0.0, {1.0});
  EXPECT_FALSE(result.ok());
  EXPECT_THAT(result.message, HasSubstr("CV_RHSFUNC_FAIL"));
  EXPECT_THAT(result.message, HasSubstr("at t = 0"));
  EXPECT_EQ(result.steps, 0);
  EXPECT_LE(result.rhs_evaluations, 2);
}

TEST(IntegrateOde, ExceptionFromRhsIsReportedNotPropagated) {
  OdeSystem system = HarmonicOscillator();
  system.rhs = [](double t, const double*, double* ydot) {
    if (t > 0.25) throw std::runtime_error("model blew up");
    ydot[0] = ydot[1] = 0;
  };
  IntegrationResult result;
  ASSERT_NO_THROW(result = IntegrateOde(system, Vec({1, 0}), 0.0, {1.0}));
  EXPECT_FALSE(result.ok());
  EXPECT_THAT(result.message, HasSubstr("rhs threw: model blew up"));
}

TEST(IntegrateOde, MaxStepsIsABudgetForTheWholeCall) {
  IntegratorOptions options;
  options.max_steps = 60;
  // 200 outputs: a per-output budget (raw SUNDIALS) would allow 12000 steps.
  const IntegrationResult result =
      IntegrateOde(HarmonicOscillator(), Vec({1, 0}), 0.0, Grid(0.1, 100.0, 200), options);
  EXPECT_FALSE(result.ok());
  EXPECT_THAT(result.message, HasSubstr("CV_TOO_MUCH_WORK"));
  EXPECT_LE(result.steps, 60);
  EXPECT_LT(result.trajectory.size(), 200);
  EXPECT_NE(result.BriefReport().find("failure"), std::string::npos);
}

// Coulomb friction written with sign(): x'' + 0.3 sign(x') + x = 0.6 cos(0.8 t)
// from rest, at the simulated start's tolerances. While v > 0,
// v(t) = c sin t - (0.6 / 0.36) 0.8 sin(0.8 t) with c = 0.6 / 0.36 - 0.3, and
// the block sticks at v's first zero; there sign(v) chatters, CVODE steps at
// ~1e-14, never at the round-off of t, and ran out the 10^7-step budget (~10 s
// in a user's `solve` of such a file). Now the pace is seen within two
// chunks, and the message says where.
TEST(IntegrateOde, AStepCrawlingAlongADiscontinuityStopsEarly) {
  OdeSystem friction;
  friction.dimension = 2;
  friction.rhs = [](double t, const double* y, double* ydot) {
    ydot[0] = y[1];
    ydot[1] = -0.3 * ((y[1] > 0) - (y[1] < 0)) - y[0] + 0.6 * std::cos(0.8 * t);
  };
  IntegratorOptions options;
  options.relative_tolerance = 1e-11;
  options.absolute_tolerance = 1e-13;
  const IntegrationResult result = IntegrateOde(friction, Vec({0, 0}), 0.0, {10.0}, options);
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result.message, HasSubstr("advanced t by"));
  EXPECT_LE(result.steps, 300'000);
  const double c = 0.6 / 0.36 - 0.3;
  auto v = [&](double t) { return c * std::sin(t) - 0.6 / 0.36 * 0.8 * std::sin(0.8 * t); };
  double lo = 1.0, hi = 2.5;  // v > 0 at 1, < 0 at 2.5
  for (int i = 0; i < 100; ++i) (v(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
  const double stopped = std::stod(result.message.substr(result.message.find("to t = ") + 7));
  EXPECT_NEAR(stopped, lo, 1e-6);  // stuck where the motion sticks
}

// x'' = a / (1 - x)^2 from rest (a MEMS plate past pull-in): x reaches 1 at
// T = pi / (2 sqrt(2 a)) with x' -> infinity, and CVODE's step falls to the
// round-off of t there. It used to keep taking steps t + h = t until the
// 10^7-step budget (16 s); now it stops within one chunk of 10^5 steps,
// saying why and where.
TEST(IntegrateOde, AStepStuckAtTheRoundOffOfTStopsEarly) {
  constexpr double a = 0.2;
  OdeSystem pull_in;
  pull_in.dimension = 2;
  pull_in.rhs = [](double, const double* y, double* ydot) {
    ydot[0] = y[1];
    ydot[1] = a / ((1 - y[0]) * (1 - y[0]));
  };
  const IntegrationResult result = IntegrateOde(pull_in, Vec({0, 0}), 0.0, {3.0}, IntegratorOptions{});
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result.message, HasSubstr("round-off of t"));
  EXPECT_LE(result.steps, 200'000);
  const double T = kPi / (2 * std::sqrt(2 * a));
  const double stopped = std::stod(result.message.substr(result.message.find("at t = ") + 7));
  EXPECT_NEAR(stopped, T, 1e-6 * T);
}

TEST(IntegrateOde, MaxStepLimitsTheStepSize) {
  IntegratorOptions options;
  options.max_step = 0.01;
  const IntegrationResult result =
      IntegrateOde(HarmonicOscillator(), Vec({1, 0}), 0.0, {1.0}, options);
  ASSERT_TRUE(result.ok()) << result.BriefReport();
  EXPECT_GE(result.steps, 100);
}

// ---- Misuse throws ----------------------------------------------------------

TEST(IntegrateOde, MisuseThrowsInvalidArgument) {
  const OdeSystem good = HarmonicOscillator();
  const Eigen::VectorXd y0 = Vec({1, 0});
  const std::vector<double> times = {1.0};
  OdeSystem zero_dimension = good;
  zero_dimension.dimension = 0;
  OdeSystem no_rhs = good;
  no_rhs.rhs = nullptr;
  EXPECT_THROW(IntegrateOde(zero_dimension, Eigen::VectorXd(), 0.0, times), std::invalid_argument);
  EXPECT_THROW(IntegrateOde(no_rhs, y0, 0.0, times), std::invalid_argument);
  EXPECT_THROW(IntegrateOde(good, Vec({1, 0, 0}), 0.0, times), std::invalid_argument);
  EXPECT_THROW(IntegrateOde(good, Vec({kNaN, 0}), 0.0, times), std::invalid_argument);
  EXPECT_THROW(IntegrateOde(good, Vec({1, HUGE_VAL}), 0.0, times), std::invalid_argument);
  EXPECT_THROW(IntegrateOde(good, y0, kNaN, times), std::invalid_argument);
  EXPECT_THROW(IntegrateOde(good, y0, 0.0, {}), std::invalid_argument);
  EXPECT_THROW(IntegrateOde(good, y0, 0.0, {1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(IntegrateOde(good, y0, 0.0, {2.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(IntegrateOde(good, y0, 0.0, {-1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(IntegrateOde(good, y0, 0.0, {1.0, kNaN}), std::invalid_argument);

  auto with = [](auto mutate) {
    IntegratorOptions options;
    mutate(options);
    return options;
  };
  using O = IntegratorOptions;
  for (const IntegratorOptions& bad : {
           with([](O& o) { o.relative_tolerance = -1e-8; }),
           with([](O& o) { o.relative_tolerance = 0; }),
           with([](O& o) { o.relative_tolerance = kNaN; }),
           with([](O& o) { o.absolute_tolerance = -1e-8; }),
           with([](O& o) { o.absolute_tolerance = 0; }),
           with([](O& o) { o.max_steps = 0; }),
           with([](O& o) { o.max_step = -1; }),
           with([](O& o) { o.initial_step = -1; }),
           with([](O& o) { o.max_order = 13; }),
           with([](O& o) { o.max_order = -1; }),
           with([](O& o) {
             o.method = Method::kBdf;
             o.max_order = 6;
           }),
       }) {
    EXPECT_THROW(IntegrateOde(good, y0, 0.0, times, bad), std::invalid_argument);
  }
}

TEST(IntegrateOde, MisuseMessageNamesTheProblem) {
  try {
    IntegrateOde(HarmonicOscillator(), Vec({1, 0, 0}), 0.0, {1.0});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("IntegrateOde"));
    EXPECT_THAT(e.what(), HasSubstr("y0 has size 3"));
  }
}

TEST(Trajectory, ComponentIsAColumnAndChecksItsIndex) {
  Trajectory trajectory;
  trajectory.times = {0, 1};
  trajectory.states.resize(2, 2);
  trajectory.states << 1, 2, 3, 4;
  EXPECT_EQ(trajectory.Component(1), Vec({2, 4}));
  EXPECT_EQ(trajectory.dimension(), 2);
  EXPECT_THROW(trajectory.Component(2), std::out_of_range);
  EXPECT_THROW(trajectory.Component(-1), std::out_of_range);
}

}  // namespace
}  // namespace rmhb::integrators

// HB-AFT on an explicit ODE evaluated pointwise (no recast), against exact
// solutions: the forced linear oscillator (one harmonic, closed form) and the
// pendulum's frequency (elliptic integral).

#include "rmhb/pointwise_collocation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "examples/references.h"

namespace rmhb {
namespace {

std::vector<Variable> States() { return {{"x", VariableRole::kState, ""}, {"x'", VariableRole::kState, ""}}; }

TEST(PointwiseCollocation, ForcedLinearOscillatorIsExact) {
  const double c = 0.1, k = 1, F = 0.7, w = 1.3;
  ExplicitOdeProblem p;
  p.names = {"x", "x'"};
  p.rhs = [=](double t, const double* y, double* dy) {
    dy[0] = y[1];
    dy[1] = -c * y[1] - k * y[0] + F * std::cos(w * t);
  };
  p.frequency = w;
  PointwiseCollocationOptions o;
  o.order = 3;
  const HarmonicSolution guess(HarmonicBasis::Periodic(1), {w}, Eigen::MatrixXd::Zero(2, 3), States());
  const HarmonicBalanceSummary s = SolvePointwiseCollocation(p, guess, o);
  ASSERT_TRUE(s.converged()) << s.solver.FullReport();
  EXPECT_EQ(s.samples[0], 16);  // power of two >= 4N + 1
  const double d = (k - w * w) * (k - w * w) + c * c * w * w;
  const Eigen::MatrixXd& X = s.solution->coefficients();
  EXPECT_NEAR(X(0, 1), F * (k - w * w) / d, 1e-14);
  EXPECT_NEAR(X(0, 2), F * c * w / d, 1e-14);
  EXPECT_NEAR(X(0, 3), 0.0, 1e-14);
  EXPECT_NEAR(X(1, 1), w * F * c * w / d, 1e-14);  // x' = w b1 cos - w a1 sin
}

ExplicitOdeProblem Pendulum(double theta0) {
  ExplicitOdeProblem p;
  p.names = {"theta", "theta'"};
  p.rhs = [](double, const double* y, double* dy) {
    dy[0] = y[1];
    dy[1] = -std::sin(y[0]);
  };
  p.frequency = 1 - theta0 * theta0 / 16;
  p.unknown_frequency = true;
  p.conditions = {PointCondition::Value(0, theta0), PointCondition::Value(1, 0.0)};
  return p;
}

TEST(PointwiseCollocation, PendulumFrequencyConvergesToTheExactOne) {
  const double a = 1.5;
  const ExplicitOdeProblem p = Pendulum(a);
  const HarmonicSolution guess = HarmonicSolution::FromAngles(
      HarmonicBasis::Periodic(1), {p.frequency}, States(), [&](const std::vector<double>& th) {
        return Eigen::Vector2d(a * std::cos(th[0]), -a * p.frequency * std::sin(th[0])).eval();
      });
  double previous = 1;
  for (int N : {5, 10, 25}) {
    PointwiseCollocationOptions o;
    o.order = N;
    const HarmonicBalanceSummary s = SolvePointwiseCollocation(p, guess, o);
    ASSERT_TRUE(s.converged()) << N << ": " << s.solver.FullReport();
    const double error = std::abs(s.solution->frequencies()[0] - examples::PendulumFrequency(a));
    EXPECT_LT(error, previous) << N;
    previous = std::max(error, 1e-16);
  }
  EXPECT_LT(previous, 1e-13);
}

TEST(PointwiseCollocation, FewSamplesAliasOversamplingDoesNot) {
  // sin(theta(t)) has every odd harmonic. At M = 2N+1 (HDHB on the original
  // equations) those above N fold back and change the solution; at M = 64 and
  // 128 the folded harmonics of this analytic solution are below round-off,
  // so both give classical HB. (Aliasing does not make the M = 2N+1 answer
  // worse here; it makes it a different discrete problem.)
  const double a = 1.5;
  const ExplicitOdeProblem p = Pendulum(a);
  const HarmonicSolution guess = HarmonicSolution::FromAngles(
      HarmonicBasis::Periodic(1), {p.frequency}, States(), [&](const std::vector<double>& th) {
        return Eigen::Vector2d(a * std::cos(th[0]), -a * p.frequency * std::sin(th[0])).eval();
      });
  auto frequency = [&](int samples) {
    PointwiseCollocationOptions o;
    o.order = 8;
    o.samples = samples;
    const HarmonicBalanceSummary s = SolvePointwiseCollocation(p, guess, o);
    EXPECT_TRUE(s.converged()) << samples;
    return s.solution->frequencies()[0];
  };
  const double w17 = frequency(17), w64 = frequency(64), w128 = frequency(128);
  EXPECT_LT(std::abs(w64 - w128), 1e-14);
  EXPECT_GT(std::abs(w17 - w64), 1e-9);
}

TEST(PointwiseCollocation, BadOptionsThrow) {
  const ExplicitOdeProblem p = Pendulum(1.0);
  const HarmonicSolution guess(HarmonicBasis::Periodic(1), {0.9}, Eigen::MatrixXd::Zero(2, 3), States());
  PointwiseCollocationOptions o;
  o.order = 0;
  EXPECT_THROW(SolvePointwiseCollocation(p, guess, o), std::invalid_argument);
  o.order = 5;
  o.samples = 4;  // below 2N+1
  EXPECT_THROW(SolvePointwiseCollocation(p, guess, o), std::invalid_argument);
  o.samples = 0;
  const HarmonicSolution wrong(HarmonicBasis::Periodic(1), {0.9}, Eigen::MatrixXd::Zero(3, 3),
                               {{"a", VariableRole::kState, ""}, {"b", VariableRole::kState, ""}, {"c", VariableRole::kState, ""}});
  EXPECT_THROW(SolvePointwiseCollocation(p, wrong, o), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb

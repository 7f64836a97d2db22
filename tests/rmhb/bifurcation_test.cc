// The bifurcation test functions on multipliers whose crossings are known by
// construction, and the rewritten problems branch switching solves: the
// period-multiplied problem (base w/2) and the two-base problem, both of
// which the period-T solution must still solve to round-off.

#include "rmhb/bifurcation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "examples/example_system.h"
#include "rmhb/branch_switching.h"
#include "rmhb/collocation_residual.h"
#include "rmhb/harmonic_balance.h"

namespace rmhb {
namespace {

using C = std::complex<double>;

Multipliers Pair(double modulus, double angle) { return {std::polar(modulus, angle), std::polar(modulus, -angle)}; }

TEST(BifurcationTestFunctions, EachCrossingFlipsItsOwnSignOnly) {
  // A real multiplier through -1 (period doubling).
  const TestFunctionSigns pd0 = TestSigns({C(-0.9), C(0.3)}, -1), pd1 = TestSigns({C(-1.1), C(0.3)}, -1);
  EXPECT_NE(pd0.minus, pd1.minus);
  EXPECT_EQ(pd0.plus, pd1.plus);
  EXPECT_EQ(pd0.torus, pd1.torus);
  // Through +1 (fold or branch point).
  const TestFunctionSigns lp0 = TestSigns({C(0.9), C(0.3)}, -1), lp1 = TestSigns({C(1.1), C(0.3)}, -1);
  EXPECT_NE(lp0.plus, lp1.plus);
  EXPECT_EQ(lp0.minus, lp1.minus);
  EXPECT_EQ(lp0.torus, lp1.torus);
  // A complex pair through the unit circle (Neimark-Sacker), with a real
  // multiplier aside.
  Multipliers ns0 = Pair(0.95, 1.0), ns1 = Pair(1.05, 1.0);
  ns0.push_back(C(0.2));
  ns1.push_back(C(0.2));
  const TestFunctionSigns t0 = TestSigns(ns0, -1), t1 = TestSigns(ns1, -1);
  EXPECT_NE(t0.torus, t1.torus);
  EXPECT_EQ(t0.plus, t1.plus);
  EXPECT_EQ(t0.minus, t1.minus);
}

TEST(BifurcationTestFunctions, NoCrossingNoFlip) {
  // A complex pair outside the circle colliding on the negative axis into
  // two real multipliers below -1: nothing crossed the circle.
  const TestFunctionSigns before = TestSigns(Pair(1.2, M_PI - 0.01), -1);
  const TestFunctionSigns after = TestSigns({C(-1.25), C(-1.15)}, -1);
  EXPECT_EQ(before.minus, after.minus);
  EXPECT_EQ(before.torus, after.torus);
  EXPECT_EQ(before.plus, after.plus);
  // The trivial multiplier of an autonomous orbit is left out.
  EXPECT_EQ(TestSigns({C(0.999999), C(0.5)}, 0).plus, TestSigns({C(1.000001), C(0.5)}, 0).plus);
}

TEST(BifurcationTestFunctions, ANeutralSaddleFlipsTheTorusSignButHasNoComplexPair) {
  const TestFunctionSigns a = TestSigns({C(2.1), C(0.5)}, -1), b = TestSigns({C(1.9), C(0.5)}, -1);
  EXPECT_NE(a.torus, b.torus);  // 2.1 * 0.5 > 1 > 1.9 * 0.5
  C mu;
  double distance = 0;
  EXPECT_FALSE(CriticalMultiplier({C(1.9), C(0.5)}, -1, BifurcationType::kNeimarkSacker, &mu, &distance));
}

TEST(BifurcationTestFunctions, CriticalMultipliers) {
  const Multipliers mu = {C(-1.02), C(0.7), std::polar(0.99, 2.0), std::polar(0.99, -2.0), C(1.01)};
  C critical;
  double d = 0;
  ASSERT_TRUE(CriticalMultiplier(mu, -1, BifurcationType::kPeriodDoubling, &critical, &d));
  EXPECT_NEAR(d, -0.02, 1e-15);
  ASSERT_TRUE(CriticalMultiplier(mu, -1, BifurcationType::kNeimarkSacker, &critical, &d));
  EXPECT_NEAR(d, -0.01, 1e-15);
  EXPECT_GT(critical.imag(), 0);
  ASSERT_TRUE(CriticalMultiplier(mu, -1, BifurcationType::kBranchPoint, &critical, &d));
  EXPECT_NEAR(d, 0.01, 1e-15);
  ASSERT_TRUE(CriticalMultiplier(mu, 4, BifurcationType::kBranchPoint, &critical, &d));  // 1.01 is trivial
  EXPECT_NEAR(d, -0.3, 1e-15);
}

// A double 1 split by an orbit's error (1 +- a, product 1) counts by its
// geometric mean; a trivial 1 beside a partner that moves the product (a
// stable 0.85, a saddle 1.5 with 0.667 elsewhere) or a complex pair does not
// pair, and the largest other |mu| is judged as before.
TEST(BifurcationTestFunctions, JudgedModulusPairsOnlyASplitDoubleOne) {
  bool paired = false;
  EXPECT_NEAR(JudgedModulus({C(1.0091), C(1 / 1.0091), C(0.5)}, 1, 1e-6, &paired), 1, 1e-12);
  EXPECT_TRUE(paired);
  EXPECT_NEAR(JudgedModulus({C(1.0091), C(1 / 1.0091), C(1.2)}, 0, 1e-6, &paired), 1.2, 1e-15);
  EXPECT_TRUE(paired);
  EXPECT_EQ(JudgedModulus({C(1), C(0.85)}, 0, 1e-6, &paired), 0.85);
  EXPECT_FALSE(paired);
  EXPECT_EQ(JudgedModulus({C(1.5), C(1), C(1 / 1.5)}, 1, 1e-6, &paired), 1.5);
  EXPECT_FALSE(paired);
  const Multipliers complex = {C(1), std::polar(1.001, 1e-3), std::polar(1.001, -1e-3)};
  EXPECT_EQ(JudgedModulus(complex, 0, 1e-6, &paired), std::abs(complex[1]));
  EXPECT_FALSE(paired);
  EXPECT_EQ(JudgedModulus({C(1.3), C(0.9)}, -1, 1e-6, &paired), 1.3);  // no trivial multiplier
  EXPECT_FALSE(paired);
}

double MaxResidual(const HarmonicBalanceProblem& problem, const HarmonicSolution& solution, int samples) {
  CollocationResidual r(problem, solution.basis(), Sampling::Uniform(samples));
  Eigen::VectorXd F;
  r.Evaluate(r.Pack(solution.coefficients(), solution.frequencies()), &F, nullptr);
  return F.lpNorm<Eigen::Infinity>();
}

TEST(BranchSwitchingProblems, ThePeriodTSolutionSolvesThePeriodDoubledProblem) {
  const examples::ExampleSetup duffing = examples::BuildExample("duffing", {{"w", 2.0}});
  HarmonicBalanceOptions options;
  options.order = 12;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(duffing.problem, duffing.guess, options);
  ASSERT_TRUE(s.converged());
  const HarmonicBalanceProblem doubled = PeriodMultiplied(duffing.problem, 2);
  EXPECT_DOUBLE_EQ(doubled.frequencies[0], 1.0);
  EXPECT_TRUE(doubled.symmetries.empty());
  const HarmonicSolution embedded = PeriodMultipliedSolution(*s.solution, 2);
  EXPECT_EQ(embedded.basis().order(), 24);
  for (double t : {0.0, 0.7, 2.9}) EXPECT_NEAR(embedded.Value(0, t), s.solution->Value(0, t), 1e-13);
  EXPECT_LT(MaxResidual(doubled, embedded, 128), 1e-12);
  // With the forcing left at harmonic 1 of the new base it would not.
  HarmonicBalanceProblem unscaled = doubled;
  unscaled.system = duffing.problem.system;
  EXPECT_GT(MaxResidual(unscaled, embedded, 128), 1e-2);
}

TEST(BranchSwitchingProblems, TheSecondBaseIsUnknownAndTheForcingStaysOnTheFirst) {
  const examples::ExampleSetup duffing = examples::BuildExample("duffing", {{"w", 2.0}});
  const HarmonicBalanceProblem two = WithSecondBase(duffing.problem, 0.3);
  ASSERT_EQ(two.frequencies.size(), 2u);
  EXPECT_EQ(two.frequencies[1], 0.3);
  EXPECT_EQ(two.unknown_frequency, (std::vector<bool>{false, true}));
  EXPECT_THROW(WithSecondBase(two, 0.2), std::invalid_argument);
  EXPECT_THROW(WithSecondBase(duffing.problem, -1), std::invalid_argument);
  EXPECT_THROW(PeriodMultiplied(duffing.problem, 0), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb

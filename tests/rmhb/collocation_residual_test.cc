#include "rmhb/collocation_residual.h"

#include <gtest/gtest.h>

#include <complex>
#include <random>

#include "examples/example_system.h"
#include "rmhb/harmonic_balance.h"

namespace rmhb {
namespace {

// Analytic Jacobian against central differences, with unknown frequency,
// point conditions, forcing, dropped constant balances and algebraic rows.
void CheckJacobian(const std::string& example, int order, bool condense = false) {
  examples::ExampleSetup e = examples::BuildExample(example);
  const HarmonicBasis basis = HarmonicBasis::Periodic(order);
  const Sampling sampling =
      Sampling::Uniform(FftFriendlySize(e.problem.system.AliasFreeSamples(order)));
  CollocationResidual r(e.problem, basis, sampling, condense);
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  const HarmonicSolution g = e.guess.OnBasis(basis);
  Eigen::VectorXd x = r.Pack(g.coefficients(), g.frequencies());
  for (int i = 0; i < x.size(); ++i) x(i) += u(gen);
  Eigen::VectorXd F, Fp, Fm;
  Eigen::MatrixXd J;
  ASSERT_TRUE(r.Evaluate(x, &F, &J));
  ASSERT_EQ(J.rows(), r.num_residuals());
  ASSERT_EQ(J.cols(), r.num_unknowns());
  const double h = 1e-6;
  double worst = 0;
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp(i) += h;
    xm(i) -= h;
    r.Evaluate(xp, &Fp, nullptr);
    r.Evaluate(xm, &Fm, nullptr);
    const Eigen::VectorXd fd = (Fp - Fm) / (2 * h);
    worst = std::max(worst, (fd - J.col(i)).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-7) << example;
}

TEST(CollocationResidual, JacobianMatchesFiniteDifferences) {
  CheckJacobian("duffing", 6);
  CheckJacobian("pendulum", 6);
  CheckJacobian("relativistic", 5);
  CheckJacobian("vanderpol", 7);
  CheckJacobian("rayleigh-plesset", 5);
}

// With x' = v condensed away, the chain rule through v = D(w) x (including
// its dependence on the unknown frequency and on the point conditions on v).
TEST(CollocationResidual, CondensedJacobianMatchesFiniteDifferences) {
  for (const char* example : {"duffing", "pendulum", "relativistic", "vanderpol", "rayleigh-plesset"})
    CheckJacobian(example, 6, true);
}

TEST(CollocationResidual, CondensationDropsTheDefinedVariableAndItsRows) {
  examples::ExampleSetup e = examples::BuildExample("vanderpol");
  CollocationResidual full(e.problem, HarmonicBasis::Periodic(10), Sampling::Uniform(41));
  CollocationResidual condensed(e.problem, HarmonicBasis::Periodic(10), Sampling::Uniform(41), true);
  EXPECT_EQ(condensed.num_condensed_variables(), 1);
  EXPECT_EQ(condensed.num_unknowns(), full.num_unknowns() - 21);
  EXPECT_EQ(condensed.num_residuals(), full.num_residuals() - 21);
  // Same discrete solution: the condensed solve reproduces u = x' exactly.
  HarmonicBalanceOptions on, off;
  on.order = off.order = 30;
  off.condense_definitions = false;
  const HarmonicBalanceSummary a = SolveHarmonicBalance(e.problem, e.guess, on);
  const HarmonicBalanceSummary b = SolveHarmonicBalance(e.problem, e.guess, off);
  ASSERT_TRUE(a.converged() && b.converged()) << a.FullReport() << b.FullReport();
  EXPECT_LT(SolutionDifference(*a.solution, *b.solution), 1e-12);
  EXPECT_LT(std::abs(a.solution->Value(1, 0.7) - a.solution->Derivative(0, 0.7)), 1e-12);
  EXPECT_EQ(a.solver.num_unknowns, b.solver.num_unknowns - 61);
}

// Condensation and a half-wave symmetry together (the forced Duffing, odd):
// the condensed, symmetric Jacobian against finite differences, half the
// unknowns, and the same solution as the full solve.
TEST(CollocationResidual, CondensationWithSymmetryHalvesTheCondensedProblem) {
  examples::ExampleSetup e = examples::BuildExample("duffing");
  e.problem.symmetries = {HalfTurnSymmetry{{1}, {-1, -1}, "odd"}};
  const HarmonicBasis basis = HarmonicBasis::Periodic(9);
  CollocationResidual r(e.problem, basis, Sampling::Uniform(40), true);
  EXPECT_EQ(r.num_condensed_variables(), 1);
  EXPECT_EQ(r.num_unknowns(), 10);  // x only, odd harmonics 1, 3, .., 9
  const HarmonicSolution g = e.guess.OnBasis(basis);
  Eigen::VectorXd x = r.Pack(g.coefficients(), g.frequencies()), F, Fp, Fm;
  for (int i = 0; i < x.size(); ++i) x(i) += 0.01 * std::sin(3.0 * i + 1);
  Eigen::MatrixXd J;
  ASSERT_TRUE(r.Evaluate(x, &F, &J));
  ASSERT_EQ(J.rows(), r.num_residuals());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp(i) += 1e-6;
    xm(i) -= 1e-6;
    r.Evaluate(xp, &Fp, nullptr);
    r.Evaluate(xm, &Fm, nullptr);
    EXPECT_LT(((Fp - Fm) / 2e-6 - J.col(i)).cwiseAbs().maxCoeff(), 1e-7) << i;
  }
  HarmonicBalanceOptions options;
  options.order = 25;
  const HarmonicBalanceSummary symmetric = SolveHarmonicBalance(e.problem, e.guess, options);
  e.problem.symmetries.clear();
  const HarmonicBalanceSummary full = SolveHarmonicBalance(e.problem, e.guess, options);
  ASSERT_TRUE(symmetric.converged() && full.converged()) << symmetric.FullReport() << full.FullReport();
  EXPECT_EQ(symmetric.solver.num_unknowns, 26);
  EXPECT_EQ(full.solver.num_unknowns, 51);
  EXPECT_LT(SolutionDifference(*symmetric.solution, *full.solution), 1e-13);
}

TEST(CollocationResidual, SizesCountDroppedBalancesAndConditions) {
  examples::ExampleSetup e = examples::BuildExample("pendulum");
  CollocationResidual r(e.problem, HarmonicBasis::Periodic(10), Sampling::Uniform(40));
  EXPECT_EQ(r.num_unknowns(), 4 * 21 + 1);
  EXPECT_EQ(r.num_residuals(), 4 * 21 - 2 + 4);
}

// Classical harmonic balance of x'' + c x' + k x + a x^3 = F cos(w t), with
// the Fourier coefficients of x^3 from an exact discrete convolution: no
// sampling at all, so it is independent of the collocation machinery.
double ClassicalDuffingResidual(const HarmonicSolution& s, const std::map<std::string, double>& p) {
  const int N = s.basis().order();
  const double w = s.frequencies()[0];
  std::vector<std::complex<double>> X(2 * N + 1);  // index m + N
  X[N] = s.coefficients()(0, 0);
  for (int k = 1; k <= N; ++k) {
    X[N + k] = 0.5 * std::complex<double>(s.coefficients()(0, 2 * k - 1), -s.coefficients()(0, 2 * k));
    X[N - k] = std::conj(X[N + k]);
  }
  double worst = 0;
  for (int m = 0; m <= N; ++m) {
    std::complex<double> cube = 0;
    for (int i = -N; i <= N; ++i)
      for (int j = -N; j <= N; ++j) {
        const int l = m - i - j;
        if (l >= -N && l <= N) cube += X[i + N] * X[j + N] * X[l + N];
      }
    const std::complex<double> iw(0, m * w);
    std::complex<double> r = (iw * iw + p.at("c") * iw + p.at("k")) * X[m + N] + p.at("a") * cube;
    if (m == 1) r -= 0.5 * p.at("F");
    worst = std::max(worst, std::abs(r));
  }
  return worst;
}

// Theorem 1: at M > (phi+1)N the collocation equations ARE classical HB; at
// M = 2N+1 (HDHB) aliasing changes the solution.
TEST(HarmonicBalance, RhbEqualsClassicalHbWhileHdhbDoesNot) {
  const std::map<std::string, double> p = {{"c", 0.1}, {"k", 1.0}, {"a", 1.0}, {"F", 2.0}, {"w", 1.8}};
  examples::ExampleSetup e = examples::BuildExample("duffing", p);
  HarmonicBalanceOptions o;
  o.order = 5;
  HarmonicBalanceSummary rhb = SolveHarmonicBalance(e.problem, e.guess, o);
  ASSERT_TRUE(rhb.converged()) << rhb.FullReport();
  EXPECT_TRUE(rhb.alias_free);
  EXPECT_EQ(rhb.samples[0], FftFriendlySize(4 * 5 + 1));
  EXPECT_LT(ClassicalDuffingResidual(*rhb.solution, p), 1e-13);

  o.rule = SamplingRule::kAft;
  HarmonicBalanceSummary aft = SolveHarmonicBalance(e.problem, e.guess, o);
  ASSERT_TRUE(aft.converged());
  EXPECT_LT((aft.solution->coefficients() - rhb.solution->coefficients()).cwiseAbs().maxCoeff(), 1e-13);

  o.rule = SamplingRule::kHdhb;
  HarmonicBalanceSummary hdhb = SolveHarmonicBalance(e.problem, e.guess, o);
  ASSERT_TRUE(hdhb.converged());
  EXPECT_FALSE(hdhb.alias_free);
  EXPECT_EQ(hdhb.samples[0], 11);
  EXPECT_GT(ClassicalDuffingResidual(*hdhb.solution, p), 1e-8);
}

TEST(HarmonicBalance, RefusesAliasedSamplesUnlessAllowed) {
  examples::ExampleSetup e = examples::BuildExample("duffing");
  HarmonicBalanceOptions o;
  o.order = 5;
  o.samples = {15};
  EXPECT_THROW(SolveHarmonicBalance(e.problem, e.guess, o), std::invalid_argument);
  o.allow_aliasing = true;
  EXPECT_NO_THROW(SolveHarmonicBalance(e.problem, e.guess, o));
  o.order = 0;
  EXPECT_THROW(SolveHarmonicBalance(e.problem, e.guess, o), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb

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
// With `symmetric`, on the subspace of the symmetries the guess has (the
// reduced J assembled in place: time reversals keep cosines or sines only).
void CheckJacobian(const std::string& example, int order, bool condense = false, bool symmetric = false) {
  examples::ExampleSetup e = examples::BuildExample(example);
  if (symmetric) {
    e.problem.symmetries = SymmetriesOf(e.guess, ImposableSymmetries(e.problem));
    ASSERT_FALSE(e.problem.symmetries.empty()) << example;
  }
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
TEST(CollocationResidual, ReducedJacobianMatchesFiniteDifferences) {
  for (const char* example : {"pendulum", "relativistic"}) {
    CheckJacobian(example, 6, false, true);
    CheckJacobian(example, 6, true, true);
  }
}

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

// The sampled maps of small known-frequency problems (METHOD.md s.21)
// against the general path on the same point: condensed or not, aliased
// (HDHB) or not, under a symmetry, and after the frequency is retuned (a
// continuation in w changes the problem under the residual).
void CheckSampledMaps(examples::ExampleSetup e, int order, int samples, bool condense) {
  const HarmonicBasis basis = HarmonicBasis::Periodic(order);
  CollocationResidual maps(e.problem, basis, Sampling::Uniform(samples), condense);
  CollocationResidual general(e.problem, basis, Sampling::Uniform(samples), condense);
  general.DisableSampledMaps();
  ASSERT_TRUE(maps.uses_sampled_maps()) << maps.num_unknowns() << " unknowns";
  ASSERT_FALSE(general.uses_sampled_maps());
  const HarmonicSolution g = e.guess.OnBasis(basis);
  Eigen::VectorXd x = maps.Pack(g.coefficients(), g.frequencies());
  for (int i = 0; i < x.size(); ++i) x(i) += 0.3 * std::sin(2.0 * i + 1);
  Eigen::VectorXd before;
  for (double w : {e.problem.frequencies[0], 0.7 * e.problem.frequencies[0]}) {
    e.problem.frequencies[0] = w;
    Eigen::VectorXd F1, F2;
    Eigen::MatrixXd J1, J2;
    ASSERT_TRUE(maps.Evaluate(x, &F1, &J1));
    ASSERT_TRUE(general.Evaluate(x, &F2, &J2));
    ASSERT_EQ(F1.size(), F2.size());
    ASSERT_EQ(J1.rows(), J2.rows());
    ASSERT_EQ(J1.cols(), J2.cols());
    const double scale = 1 + J2.cwiseAbs().maxCoeff();
    EXPECT_LT((F1 - F2).cwiseAbs().maxCoeff(), 1e-13 * scale) << "w = " << w;
    EXPECT_LT((J1 - J2).cwiseAbs().maxCoeff(), 1e-13 * scale) << "w = " << w;
    Eigen::VectorXd F3;
    ASSERT_TRUE(maps.Evaluate(x, &F3, nullptr));
    EXPECT_EQ(F3, F1);
    if (before.size()) {
      EXPECT_GT((F1 - before).cwiseAbs().maxCoeff(), 1e-3);  // retuned, not stale
    }
    before = F1;
  }
  // Samples whose cube overflows: not admissible, on either path.
  const Eigen::VectorXd huge = Eigen::VectorXd::Constant(x.size(), 1e120);
  Eigen::VectorXd F1, F2;
  EXPECT_FALSE(maps.Evaluate(huge, &F1, nullptr));
  EXPECT_FALSE(general.Evaluate(huge, &F2, nullptr));
  EXPECT_TRUE(std::isinf(F1(0)));
}

TEST(CollocationResidual, SampledMapsAgreeWithTheGeneralPath) {
  CheckSampledMaps(examples::BuildExample("duffing"), 3, 14, true);   // RHB, the Monte Carlo's
  CheckSampledMaps(examples::BuildExample("duffing"), 3, 7, true);    // HDHB, aliased
  CheckSampledMaps(examples::BuildExample("duffing"), 3, 14, false);  // x and v both unknown
  CheckSampledMaps(examples::BuildExample("rayleigh-plesset"), 3, 16, true);  // recast, time terms
  examples::ExampleSetup odd = examples::BuildExample("duffing");
  odd.problem.symmetries = {HalfTurnSymmetry{{1}, {-1, -1}, "odd"}};
  CheckSampledMaps(odd, 9, 40, true);  // 10 unknowns of 19
}

TEST(CollocationResidual, SampledMapsOnlyForSmallKnownFrequencyProblems) {
  const examples::ExampleSetup duffing = examples::BuildExample("duffing");
  EXPECT_FALSE(CollocationResidual(duffing.problem, HarmonicBasis::Periodic(10), Sampling::Uniform(41), true)
                   .uses_sampled_maps());  // 21 unknowns
  const examples::ExampleSetup vanderpol = examples::BuildExample("vanderpol");
  EXPECT_FALSE(CollocationResidual(vanderpol.problem, HarmonicBasis::Periodic(3), Sampling::Uniform(13), true)
                   .uses_sampled_maps());  // unknown frequency and a point condition
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

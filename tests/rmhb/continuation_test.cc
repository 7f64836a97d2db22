// Parameter continuation against independent references: the Duffing
// frequency response through both folds (fold frequencies from a direct
// high-order solve in another parameterisation, branch points against CVODE
// integrations of the original equation), and the relativistic oscillator's
// exact energy-quadrature amplitude and frequency along beta.

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "examples/example_system.h"
#include "examples/references.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/continuation.h"

namespace rmhb {
namespace {

// x'' + 0.1 x' + x + x^3 = 0.5 cos(w t): a hardening frequency response
// that bends over between w ~ 1.44 and w ~ 2.21.
constexpr double kDamping = 0.1, kForce = 0.5;

examples::ExampleSetup Duffing(double w) {
  return examples::BuildExample("duffing", {{"c", kDamping}, {"F", kForce}, {"w", w}});
}

ContinuationProblem DuffingSweep(double from, double to) {
  ContinuationProblem problem;
  problem.parameter = "w";
  problem.start = from;
  problem.end = to;
  problem.build = [](double w) { return Duffing(w).problem; };
  return problem;
}

// One-harmonic balance x = a cos(w t) + b sin(w t) of amplitude A on the
// branch left (root = -1) or right (+1) of the backbone:
// (K^2 + c^2 w^2) A^2 = F^2, K = 1 + 3/4 A^2 - w^2, a quadratic in w^2.
// NaN where that branch has no point of amplitude A.
double OneHarmonicFrequency(double A, int root) {
  const double k = 1 + 0.75 * A * A, b = 2 * k - kDamping * kDamping;
  const double c = k * k - kForce * kForce / (A * A);
  return std::sqrt((b + root * std::sqrt(b * b - 4 * c)) / 2);
}

HarmonicSolution OneHarmonic(double A, int root) {
  const double w = OneHarmonicFrequency(A, root), K = 1 + 0.75 * A * A - w * w;
  const double D = K * K + kDamping * kDamping * w * w;
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(2, 3);
  g(0, 1) = kForce * K / D;
  g(0, 2) = kForce * kDamping * w / D;
  g(1, 1) = w * g(0, 2);
  g(1, 2) = -w * g(0, 1);
  return HarmonicSolution(HarmonicBasis::Periodic(1), {w}, g, Duffing(w).problem.system.variables());
}

// The fold frequency without continuation: parameterise the branch by
// s = x(0) instead, with the forcing frequency as the unknown of a direct
// order-25 solve; w(s) has its extremum at the fold, found by golden-section
// search from the one-harmonic estimate. root -1: the maximum (upper fold),
// +1: the minimum (lower fold).
double IndependentFoldFrequency(int root) {
  double A_fold = 0, w_fold = root < 0 ? 0 : 1e9;
  for (double A = 0.3; A < 2.4; A += 1e-4) {  // one-harmonic fold estimate
    const double w = OneHarmonicFrequency(A, root);
    if (std::isfinite(w) && root * (w_fold - w) > 0) w_fold = w, A_fold = A;
  }
  HarmonicSolution guess = OneHarmonic(A_fold, root);
  HarmonicBalanceProblem problem = Duffing(w_fold).problem;
  problem.unknown_frequency = {true};
  HarmonicBalanceOptions options;
  options.order = 25;
  auto w_at = [&](double s) {
    problem.conditions = {PointCondition::Value(0, s, "x(0) = s")};
    const HarmonicBalanceSummary solved = SolveHarmonicBalance(problem, guess, options);
    EXPECT_TRUE(solved.converged()) << solved.FullReport();
    guess = *solved.solution;
    return root * solved.solution->frequencies()[0];  // minimised
  };
  const double s0 = guess.coefficients()(0, 1), g = (std::sqrt(5.0) - 1) / 2;
  double a = s0 - 0.2, b = s0 + 0.2, c = b - g * (b - a), d = a + g * (b - a);
  double fc = w_at(c), fd = w_at(d);
  while (b - a > 1e-9) {
    if (fc < fd) {
      b = d, d = c, fd = fc, c = b - g * (b - a), fc = w_at(c);
    } else {
      a = c, c = d, fc = fd, d = a + g * (b - a), fd = w_at(d);
    }
  }
  return root * std::min(fc, fd);
}

TEST(Continuation, DuffingPseudoArclengthPassesBothFoldsAtTheIndependentFrequencies) {
  ContinuationOptions options;
  options.harmonic_balance.order = 15;
  const ContinuationSummary s = TraceBranch(DuffingSweep(0.5, 3.0), Duffing(0.5).guess, options);
  ASSERT_TRUE(s.completed()) << s.FullReport();
  EXPECT_EQ(s.points.front().parameter, 0.5);
  EXPECT_EQ(s.points.back().parameter, 3.0);
  ASSERT_EQ(s.num_folds, 2) << s.FullReport();
  std::vector<double> folds;
  for (const ContinuationPoint& p : s.points)
    if (p.fold) folds.push_back(p.parameter);
  ASSERT_EQ(folds.size(), 2u) << s.FullReport();
  // Jump-down (upper) fold first, then the jump-up (lower) one.
  // Measured: they agree to 4e-16 and 2e-16.
  EXPECT_NEAR(folds[0], IndependentFoldFrequency(-1), 1e-12);
  EXPECT_NEAR(folds[1], IndependentFoldFrequency(+1), 1e-12);

  for (const ContinuationPoint& p : s.points) {
    EXPECT_LT(p.residual, 1e-12) << p.parameter;
    // Between the folds the branch runs backwards in w.
    if (!p.fold) {
      EXPECT_EQ(p.tangent_parameter < 0, p.folds_before == 1) << p.parameter;
      // ... and is the unstable (saddle) one, by Hill's method.
      EXPECT_EQ(p.stability, p.folds_before == 1 ? PointStability::kUnstable : PointStability::kStable)
          << p.parameter;
    } else {
      EXPECT_LT(std::abs(p.max_real_part), 1e-6) << p.parameter;  // a multiplier crosses 1 here
    }
  }
}

TEST(Continuation, DuffingBranchPointsAreSolutionsOfTheOriginalEquation) {
  ContinuationOptions options;
  options.harmonic_balance.order = 15;
  options.stability = false;  // tested above
  const ContinuationSummary s = TraceBranch(DuffingSweep(1.2, 2.5), Duffing(1.2).guess, options);
  ASSERT_TRUE(s.completed()) << s.FullReport();
  ASSERT_EQ(s.num_folds, 2);
  // Upper, unstable middle and lower branch: each point integrated over a
  // period from its own initial state stays on it (CVODE Adams, rtol 1e-13).
  int checked = 0;
  for (size_t i = 0; i < s.points.size(); i += 4) {
    const ContinuationPoint& p = s.points[i];
    const examples::ExampleSetup e = Duffing(p.parameter);
    const auto report = integrators::ValidateTrajectory(
        {e.original.dimension(), e.original.rhs},
        [&](double t) { return e.original.state(p.solution, t); }, 2 * M_PI / p.parameter, false, 201);
    ASSERT_TRUE(report.ok) << report.message;
    EXPECT_LT(report.max_error, 1e-9) << "w = " << p.parameter << " " << p.folds_before;
    ++checked;
  }
  EXPECT_GE(checked, 5);
}

// With a target the first solve chooses its order (here 8 -> more): the
// branch is continued on the basis that solve chose, not on the options'
// (it once packed the chosen solution into the options' smaller basis and
// reported the larger order).
TEST(Continuation, KeepsTheOrderTheFirstSolveChose) {
  ContinuationOptions options;
  options.harmonic_balance.order = 8;
  options.harmonic_balance.tolerance = 1e-12;
  options.stability = false;
  const ContinuationSummary s = TraceBranch(DuffingSweep(1.2, 1.3), Duffing(1.2).guess, options);
  ASSERT_TRUE(s.completed()) << s.FullReport();
  EXPECT_GT(s.order, 8);
  for (const ContinuationPoint& p : s.points) {
    EXPECT_EQ(p.solution.basis().order(), s.order);
    EXPECT_LE(p.residual, 1e-14);
  }
  const HarmonicBalanceSummary direct = SolveHarmonicBalance(Duffing(1.2).problem, Duffing(1.2).guess,
                                                             options.harmonic_balance);
  ASSERT_TRUE(direct.converged());
  EXPECT_LE(SolutionDifference(*direct.solution, s.points.front().solution), 1e-13);
}

TEST(Continuation, NaturalParameterStopsAtTheFoldAndSaysSo) {
  ContinuationOptions options;
  options.method = ContinuationMethod::kNatural;
  options.harmonic_balance.order = 15;
  const ContinuationSummary s = TraceBranch(DuffingSweep(1.5, 3.0), Duffing(1.5).guess, options);
  EXPECT_EQ(s.status, ContinuationStatus::kStepTooSmall) << s.FullReport();
  EXPECT_NE(s.message.find("turning point"), std::string::npos) << s.message;
  ASSERT_FALSE(s.points.empty());
  EXPECT_GT(s.points.back().parameter, 2.2);
  EXPECT_LT(s.points.back().parameter, 2.2119353170197);
  EXPECT_GT(s.points.back().solution.Amplitude(0), 2);  // still on the upper branch
}

// beta -> 1 makes the velocity a square wave: the fixed order's truncation
// error grows from round-off to ~1e-4 at 0.99, which is what this checks
// (continuation adds nothing to it: see the direct solve at the end).
// Measured at N = 80: <= 1.3e-15 up to 0.88, 8.4e-13 at 0.929, 9.3e-7 at 0.978,
// 2.9e-4 at 0.99.
double RelativisticTolerance(double beta) {
  return beta < 0.9 ? 1e-12 : beta < 0.95 ? 1e-10 : beta < 0.98 ? 1e-5 : 1e-3;
}

TEST(Continuation, RelativisticNaturalSweepMatchesTheEnergyQuadrature) {
  ContinuationProblem problem;
  problem.parameter = "beta";
  problem.start = 0.5;
  problem.end = 0.99;
  problem.build = [](double beta) {
    return examples::BuildExample("relativistic", {{"beta", beta}}).problem;
  };
  ContinuationOptions options;
  options.method = ContinuationMethod::kNatural;
  options.harmonic_balance.order = 80;
  const ContinuationSummary s =
      TraceBranch(problem, examples::BuildExample("relativistic", {{"beta", 0.5}}).guess, options);
  ASSERT_TRUE(s.completed()) << s.FullReport();
  EXPECT_GE(s.points.size(), 8u);
  EXPECT_EQ(s.points.back().parameter, 0.99);
  // A conservative orbit: its second +1 multiplier wanders within 1e-6 of +1
  // as a real pair or a complex one, which is no bifurcation.
  EXPECT_TRUE(s.bifurcations.empty()) << s.FullReport();
  for (const ContinuationPoint& p : s.points) {
    const double beta = p.parameter;
    EXPECT_NEAR(p.solution.Amplitude(0), examples::RelativisticAmplitude(beta), RelativisticTolerance(beta))
        << beta;
    EXPECT_NEAR(p.solution.frequencies()[0], 2 * M_PI / examples::RelativisticPeriod(beta),
                RelativisticTolerance(beta))
        << beta;
  }
  // The last point is the direct solve at the same order, to round-off.
  const examples::ExampleSetup e = examples::BuildExample("relativistic", {{"beta", 0.99}});
  HarmonicBalanceOptions direct;
  direct.order = 80;
  const HarmonicBalanceSummary d = SolveHarmonicBalance(e.problem, e.guess, direct);
  ASSERT_TRUE(d.converged());
  EXPECT_NEAR(s.points.back().solution.frequencies()[0], d.solution->frequencies()[0], 1e-13);
}

TEST(Continuation, PseudoArclengthOnAnOverdeterminedConservativeProblem) {
  // Two point conditions for one unknown frequency: the bordered system is
  // least squares (QR), the tangent too.
  ContinuationProblem problem;
  problem.parameter = "beta";
  problem.start = 0.3;
  problem.end = 0.8;
  problem.build = [](double beta) {
    return examples::BuildExample("relativistic", {{"beta", beta}}).problem;
  };
  ContinuationOptions options;
  options.harmonic_balance.order = 40;
  const ContinuationSummary s =
      TraceBranch(problem, examples::BuildExample("relativistic", {{"beta", 0.3}}).guess, options);
  ASSERT_TRUE(s.completed()) << s.FullReport();
  EXPECT_EQ(s.num_folds, 0);
  for (const ContinuationPoint& p : s.points) {
    EXPECT_NEAR(p.solution.Amplitude(0), examples::RelativisticAmplitude(p.parameter), 1e-11) << p.parameter;
    EXPECT_GT(p.tangent_parameter, 0);
  }
}

TEST(Continuation, QuasiPeriodicBranchOnTheTorusEndsOnTheDirectSolve) {
  // Duffing forced at 0.7 and 1.1 (two known bases), first tone's amplitude
  // from 0.5 to 1.5: every point is a torus; the last one is the solution a
  // direct solve at F1 = 1.5 finds from the example's own guess.
  ContinuationProblem problem;
  problem.parameter = "F1";
  problem.start = 0.5;
  problem.end = 1.5;
  problem.build = [](double F1) { return examples::BuildExample("duffing-2tone", {{"F1", F1}}).problem; };
  const examples::ExampleSetup start = examples::BuildExample("duffing-2tone", {{"F1", 0.5}});
  ContinuationOptions options;
  options.harmonic_balance.order = 4;
  const ContinuationSummary s = TraceBranch(problem, start.guess, options);
  ASSERT_TRUE(s.completed()) << s.FullReport();
  EXPECT_GE(s.points.size(), 5u);
  EXPECT_EQ(s.stability_note,
            "quasi-periodic solutions have no period: neither Hill's method nor a monodromy matrix applies");
  for (const ContinuationPoint& p : s.points) {
    EXPECT_EQ(p.solution.frequencies(), (std::vector<double>{0.7, 1.1}));
    EXPECT_LT(p.residual, 1e-13);
  }
  const examples::ExampleSetup end = examples::BuildExample("duffing-2tone", {{"F1", 1.5}});
  const HarmonicBalanceSummary direct = SolveHarmonicBalance(end.problem, end.guess, options.harmonic_balance);
  ASSERT_TRUE(direct.converged());
  EXPECT_LT((s.points.back().solution.coefficients() - direct.solution->coefficients()).cwiseAbs().maxCoeff(),
            1e-12);
}

TEST(Continuation, AValueOutsideTheModelsDomainEndsTheTraceWithItsReason) {
  ContinuationProblem problem;
  problem.parameter = "beta";
  problem.start = 0.9;
  problem.end = 1.2;
  problem.build = [](double beta) {
    return examples::BuildExample("relativistic", {{"beta", beta}}).problem;
  };
  ContinuationOptions options;
  options.method = ContinuationMethod::kNatural;
  options.harmonic_balance.order = 20;
  options.initial_step = options.max_step = 0.2;  // 1.1, 1.0 refused, then 0.95
  options.min_step = 0.05;
  const ContinuationSummary s =
      TraceBranch(problem, examples::BuildExample("relativistic", {{"beta", 0.9}}).guess, options);
  EXPECT_EQ(s.status, ContinuationStatus::kStepTooSmall);
  EXPECT_LT(s.points.back().parameter, 1.0);
  EXPECT_EQ(s.rejected_steps, 3) << s.FullReport();
  EXPECT_NE(s.message.find("beta must be in (0, 1)"), std::string::npos) << s.message;
}

TEST(Continuation, MisuseThrows) {
  ContinuationOptions options;
  const HarmonicSolution guess = Duffing(1).guess;
  EXPECT_THROW(TraceBranch(DuffingSweep(1, 1), guess, options), std::invalid_argument);
  EXPECT_THROW(TraceBranch(DuffingSweep(1, NAN), guess, options), std::invalid_argument);
  ContinuationProblem no_build = DuffingSweep(1, 2);
  no_build.build = nullptr;
  EXPECT_THROW(TraceBranch(no_build, guess, options), std::invalid_argument);
  ContinuationOptions bad = options;
  bad.step_shrink = 1.5;
  EXPECT_THROW(TraceBranch(DuffingSweep(1, 2), guess, bad), std::invalid_argument);
  bad = options;
  bad.max_step = 0.1;
  bad.initial_step = 0.2;
  EXPECT_THROW(TraceBranch(DuffingSweep(1, 2), guess, bad), std::invalid_argument);
  // A build whose structure changes along the way.
  ContinuationProblem changing = DuffingSweep(1, 2);
  changing.build = [](double w) {
    HarmonicBalanceProblem p = Duffing(w).problem;
    if (w > 1.05) p.conditions.push_back(PointCondition::Value(0, 0.1, "x(0) = 0.1"));
    return p;
  };
  EXPECT_THROW(TraceBranch(changing, guess, options), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb

// Quasi-periodic responses on a 2-torus (RMHB, rmhb/METHOD.md s.6): the issue's
// must-show items against tight CVODE trajectories of the ORIGINAL equations,
// the two samplings (torus grid, GCD rule), rational ratios, the spectrum-
// shaped bases and the half-turn symmetry reduction.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "examples/example_system.h"
#include "integrators/cvode_integrator.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/symmetry.h"

namespace rmhb {
namespace {

// The automatic path every model takes (rmhb solve's defaults, METHOD.md
// s.8): the symmetries of the equations that the guess has, imposed; the
// adaptive index set from the diamond of the default order to `tolerance`.
HarmonicBalanceProblem WithSymmetries(const examples::ExampleSetup& e) {
  HarmonicBalanceProblem problem = e.problem;
  problem.symmetries =
      SymmetriesOf(e.guess, DetectHalfTurnSymmetries(problem.system, static_cast<int>(problem.frequencies.size())));
  return problem;
}

HarmonicBalanceSummary Solve(const examples::ExampleSetup& e, double tolerance = 1e-10) {
  HarmonicBalanceOptions o;
  o.order = e.default_order;
  o.shape = BasisShape::kAdaptive;
  o.tolerance = tolerance;
  return SolveHarmonicBalance(WithSymmetries(e), e.guess, o);
}

// ---- 1. Asymmetric pendulum, both base frequencies unknown -----------------

// Paper: p = 5 diamond with FFT-fixed w = (0.9857, 0.9935): error 9.21e-3 in x,
// 3.9e-7 in y. Here the frequencies are solved for on the adaptive index set,
// with the two reflections detected on the equations.
TEST(AsymmetricPendulum, MatchesCvodeOverTwoThousandTimeUnits) {
  const examples::ExampleSetup e = examples::BuildExample("asym-pendulum");
  const HarmonicBalanceSummary s = Solve(e);
  EXPECT_EQ(WithSymmetries(e).symmetries.size(), 2u);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  const HarmonicSolution& sol = *s.solution;
  // w1 ~ 0.985125, w2 ~ 0.992829 (the FFT estimates are off in the 4th digit).
  EXPECT_NEAR(sol.frequencies()[0], 0.98512470168, 1e-9);
  EXPECT_NEAR(sol.frequencies()[1], 0.99282862390, 1e-9);

  integrators::IntegratorOptions tight;
  tight.relative_tolerance = 1e-13;
  tight.absolute_tolerance = 1e-15;
  std::vector<double> times;
  for (int i = 0; i <= 4000; ++i) times.push_back(0.5 * i);
  const integrators::IntegrationResult r = integrators::IntegrateOde(
      {4, e.original.rhs}, Eigen::Vector4d(0.1, 0.2, 0.0, 0.0), 0.0, times, tight);
  ASSERT_TRUE(r.ok()) << r.message;
  double error_x = 0, error_y = 0;
  for (size_t i = 0; i < times.size(); ++i) {
    error_x = std::max(error_x, std::abs(sol.Value(0, times[i]) - r.trajectory.states(i, 0)));
    error_y = std::max(error_y, std::abs(sol.Value(1, times[i]) - r.trajectory.states(i, 1)));
  }
  EXPECT_LT(error_x, 1e-8);
  EXPECT_LT(error_y, 1e-8);
}

// Four conditions, two unknown frequencies: the balances alone lose rank by
// 4 (two phases, two actions), the conditions restore it. A rank-deficient
// J would leave a frequency free.
TEST(AsymmetricPendulum, FrequenciesAreDetermined) {
  const examples::ExampleSetup e = examples::BuildExample("asym-pendulum");
  HarmonicBalanceOptions o;
  o.order = 3;
  o.solver.estimate_condition = true;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(e.problem, e.guess, o);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  EXPECT_EQ(s.solver.num_residuals, s.solver.num_unknowns + 2);
  EXPECT_LT(s.solver.condition_estimate, 1e6) << s.FullReport();
  EXPECT_GT(s.solver.condition_estimate, 1.0);
}

// The error follows the target: each solve within its tolerance (checked
// on the frequencies against a solve at 1e-12), the index set growing.
TEST(AsymmetricPendulum, ErrorFollowsTheTarget) {
  const examples::ExampleSetup e = examples::BuildExample("asym-pendulum");
  const HarmonicBalanceSummary best = Solve(e, 1e-12);
  ASSERT_TRUE(best.converged());
  int previous = 0;
  for (double tolerance : {1e-4, 1e-6, 1e-8}) {
    const HarmonicBalanceSummary s = Solve(e, tolerance);
    ASSERT_TRUE(s.converged()) << "tolerance " << tolerance << "\n" << s.FullReport();
    for (int b = 0; b < 2; ++b)
      EXPECT_LT(std::abs(s.solution->frequencies()[b] - best.solution->frequencies()[b]), tolerance);
    EXPECT_LE(s.truncation_estimate, tolerance);
    EXPECT_GT(s.solution->basis().size(), previous);
    previous = s.solution->basis().size();
  }
}

// ---- 2. Forced Van der Pol, forcing known, limit-cycle frequency unknown ---

TEST(ForcedVanDerPol, MatchesCvodeOverFiveHundredTimeUnits) {
  const examples::ExampleSetup e = examples::BuildExample("forced-vanderpol");
  const HarmonicBalanceSummary s = Solve(e);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  const HarmonicSolution& sol = *s.solution;
  EXPECT_EQ(sol.frequencies()[0], 2.3);
  EXPECT_NEAR(sol.frequencies()[1], 0.997466254703, 1e-11);
  // Not locked: w1/w2 = 2.3058424 is no ratio of small integers (a locked
  // response would be periodic and the torus check below would fail).
  const double ratio = sol.frequencies()[0] / sol.frequencies()[1];
  for (int q = 1; q <= 12; ++q)
    EXPECT_GT(std::abs(ratio * q - std::round(ratio * q)), 1e-3) << "near " << std::round(ratio * q) << "/" << q;
  // Phases matched: CVODE starts from the solution's state at t = 0, on the
  // attracting torus, so any error shows the torus or its flow is wrong.
  const auto report = integrators::ValidateTrajectory(
      {2, e.original.rhs}, [&](double t) { return e.original.state(sol, t); }, 500.0, false, 5001);
  ASSERT_TRUE(report.ok) << report.message;
  EXPECT_LT(report.max_error, 1e-8) << "at t = " << report.error_time;  // measured 6e-10
  EXPECT_NEAR(sol.Derivative(0, 0.0), 0.0, 1e-12);  // the phase condition
}

// The adaptive index set and the paper's diamond are the same torus where
// both are accurate.
TEST(ForcedVanDerPol, AdaptiveSetAndPlainDiamondAgree) {
  const examples::ExampleSetup e = examples::BuildExample("forced-vanderpol");
  const HarmonicBalanceSummary adaptive = Solve(e);
  HarmonicBalanceOptions o;
  o.order = 15;
  o.shape = BasisShape::kDiamond;
  const HarmonicBalanceSummary diamond = SolveHarmonicBalance(e.problem, e.guess, o);
  ASSERT_TRUE(adaptive.converged() && diamond.converged());
  EXPECT_NEAR(adaptive.solution->frequencies()[1], diamond.solution->frequencies()[1], 1e-12);
  double worst = 0;
  for (int i = 0; i <= 400; ++i)
    worst = std::max(worst, std::abs(adaptive.solution->Value(0, 0.25 * i) -
                                     diamond.solution->Value(0, 0.25 * i)));
  EXPECT_LT(worst, 3e-8);  // the diamond's truncation error, ~1e-8
}

// ---- 3. Torus grid and GCD rule ----------------------------------------------

double MaxDifference(const HarmonicBalanceSummary& a, const HarmonicBalanceSummary& b) {
  return (a.solution->coefficients() - b.solution->coefficients()).cwiseAbs().maxCoeff();
}

// Both are alias-free projections, hence classical HB on the same harmonics,
// as long as no two harmonics of the products share a frequency: for r1 : r2
// the resonance has order r1 + r2, beyond (phi + 1) p = 16 at p = 4 for 7 : 11
// and at p = 2 for 3 : 5 (order 8, with the odd symmetry).
TEST(GcdRule, EqualsTorusGridBelowTheResonance) {
  struct Case {
    double w1, w2;
    int order;
    std::vector<int> ratios;
  };
  for (const Case& c : {Case{0.7, 1.1, 4, {7, 11}}, Case{0.6, 1.0, 2, {3, 5}}}) {
    const examples::ExampleSetup e =
        examples::BuildExample("duffing-2tone", {{"w1", c.w1}, {"w2", c.w2}});
    HarmonicBalanceOptions o;
    o.order = c.order;
    const HarmonicBalanceSummary torus = SolveHarmonicBalance(e.problem, e.guess, o);
    o.quasi_periodic_sampling = QuasiPeriodicSampling::kGcd;
    const HarmonicBalanceSummary gcd = SolveHarmonicBalance(e.problem, e.guess, o);
    ASSERT_TRUE(torus.converged() && gcd.converged()) << torus.FullReport() << gcd.FullReport();
    EXPECT_EQ(torus.samples.size(), 2u);
    EXPECT_EQ(gcd.samples.size(), 1u);
    EXPECT_LT(gcd.samples[0], torus.samples[0] * torus.samples[1]);  // why the rule exists
    EXPECT_LT(MaxDifference(torus, gcd), 1e-12) << c.w1 << " : " << c.w2;
    EXPECT_EQ(RationalRatios({c.w1, c.w2}, 1e-12, 1000), c.ratios);
  }
}

// Past the resonance the two solve different problems: the GCD rule the
// periodic one (5 w1 - 3 w2 = 0 makes (m, n) and (m + 5, n - 3) one
// frequency), the torus grid the quasi-periodic one. Then the GCD rule must
// refuse a basis that holds both.
TEST(GcdRule, DiffersPastTheResonanceAndRefusesResonantBases) {
  const examples::ExampleSetup e =
      examples::BuildExample("duffing-2tone", {{"w1", 0.6}, {"w2", 1.0}});
  HarmonicBalanceOptions o;
  o.order = 3;
  const HarmonicBalanceSummary torus = SolveHarmonicBalance(e.problem, e.guess, o);
  o.quasi_periodic_sampling = QuasiPeriodicSampling::kGcd;
  const HarmonicBalanceSummary gcd = SolveHarmonicBalance(e.problem, e.guess, o);
  ASSERT_TRUE(torus.converged() && gcd.converged());
  EXPECT_GT(MaxDifference(torus, gcd), 1e-6);
  o.order = 4;
  try {
    SolveHarmonicBalance(e.problem, e.guess, o);
    ADD_FAILURE() << "expected the GCD rule to refuse a basis across the 3:5 resonance";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("same frequency for ratios 3:5"), std::string::npos)
        << error.what();
  }
}

// The paper's FFT frequencies taken as exact: 9857 : 9935, a period 2 pi / 1e-4.
TEST(GcdRule, RefusesAnImpracticalSampleCountAndNamesIt) {
  examples::ExampleSetup e = examples::BuildExample("asym-pendulum");
  e.problem.frequencies = {0.9857, 0.9935};
  e.problem.unknown_frequency = {false, false};
  HarmonicBalanceOptions o;
  o.order = 5;  // the paper's diamond
  o.quasi_periodic_sampling = QuasiPeriodicSampling::kGcd;
  try {
    SolveHarmonicBalance(e.problem, e.guess, o);
    ADD_FAILURE() << "expected the GCD rule to be refused";
  } catch (const std::invalid_argument& error) {
    const std::string what = error.what();
    // (phi + 1) p max(r) + 1 = 4 * 5 * 9935 + 1 against a 21 x 21 torus grid.
    EXPECT_NE(what.find("198701 samples"), std::string::npos) << what;
    EXPECT_NE(what.find("9857:9935"), std::string::npos) << what;
    EXPECT_NE(what.find("torus grid"), std::string::npos) << what;
  }
  // The same basis on the torus grid is cheap.
  o.quasi_periodic_sampling = QuasiPeriodicSampling::kTorus;
  o.solver.method = SolverMethod::kNewton;
  o.solver.max_iterations = 5;
  EXPECT_NO_THROW(SolveHarmonicBalance(e.problem, e.guess, o));
}

TEST(RationalRatios, FindsSmallIntegerRatios) {
  EXPECT_EQ(RationalRatios({0.6, 1.0}, 1e-12, 1000), (std::vector<int>{3, 5}));
  EXPECT_EQ(RationalRatios({1.0, 0.6}, 1e-12, 1000), (std::vector<int>{5, 3}));
  EXPECT_EQ(RationalRatios({3.0, 5.0}, 1e-12, 1000), (std::vector<int>{3, 5}));
  EXPECT_EQ(RationalRatios({2.0, 4.0}, 1e-12, 1000), (std::vector<int>{1, 2}));
  EXPECT_EQ(RationalRatios({0.5, 0.75, 1.25}, 1e-12, 1000), (std::vector<int>{2, 3, 5}));
  EXPECT_EQ(RationalRatios({0.9857, 0.9935}, 1e-12, 100000), (std::vector<int>{9857, 9935}));
  // The tolerance decides what counts as rational.
  EXPECT_EQ(RationalRatios({0.6 + 1e-9, 1.0}, 1e-6, 1000), (std::vector<int>{3, 5}));
  EXPECT_THROW(RationalRatios({0.6 + 1e-9, 1.0}, 1e-13, 1000), std::invalid_argument);
}

TEST(RationalRatios, RefusesIrrationalLookingRatiosWithAReason) {
  try {
    RationalRatios({1.0, std::sqrt(2.0)}, 1e-12, 1000);
    ADD_FAILURE() << "sqrt(2) has no small rational approximation";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("torus grid"), std::string::npos) << error.what();
  }
  EXPECT_THROW(RationalRatios({}, 1e-12, 1000), std::invalid_argument);
}

// ---- Bases and symmetries ------------------------------------------------------

TEST(HarmonicBasis, FromHarmonicsNormalisesSignsAndDuplicates) {
  const HarmonicBasis b =
      HarmonicBasis::FromHarmonics(2, {{-1, 2}, {1, -2}, {0, 0}, {0, 3}, {2, 0}}, 2, "test");
  EXPECT_EQ(b.size(), 4);  // zero, (1, -2), (0, 3), (2, 0)
  EXPECT_EQ(b.harmonic(0), (std::vector<int>{0, 0}));
  EXPECT_GE(b.Find({-1, 2}), 1);
  EXPECT_EQ(b.Find({1, 2}), -1);
  EXPECT_EQ(b.Reach(0), 2);
  EXPECT_EQ(b.Reach(1), 3);
  EXPECT_EQ(b.order(), 2);
  EXPECT_THROW(HarmonicBasis::FromHarmonics(2, {{1, 2, 3}}, 1, "bad"), std::invalid_argument);
}

TEST(HarmonicBasis, WeightedDiamondStretchesAlongLightBases) {
  const HarmonicBasis b = HarmonicBasis::WeightedDiamond({2, 1}, 6);
  EXPECT_EQ(b.Reach(0), 3);
  EXPECT_EQ(b.Reach(1), 6);
  EXPECT_GE(b.Find({2, 2}), 1);
  EXPECT_EQ(b.Find({2, 3}), -1);
  EXPECT_EQ(HarmonicBasis::WeightedDiamond({1, 1}, 4).size(), HarmonicBasis::Diamond(2, 4).size());
  EXPECT_THROW(HarmonicBasis::WeightedDiamond({0, 1}, 4), std::invalid_argument);
}

// The reduction only removes what the symmetry forces to zero: with and
// without it the solution is the same, with half the unknowns per symmetry.
TEST(HalfTurnSymmetry, ReducedAndFullSolvesAgree) {
  const examples::ExampleSetup e = examples::BuildExample("asym-pendulum");
  const HarmonicBalanceProblem reduced = WithSymmetries(e);
  ASSERT_EQ(reduced.symmetries.size(), 2u);
  HarmonicBalanceOptions o;
  o.order = 3;
  o.condense_definitions = false;  // count the unknowns of the same layout
  const HarmonicBalanceSummary reduced_solve = SolveHarmonicBalance(reduced, e.guess, o);
  const HarmonicBalanceSummary full_solve = SolveHarmonicBalance(e.problem, e.guess, o);
  ASSERT_TRUE(reduced_solve.converged() && full_solve.converged());
  // Each variable keeps one parity class of four (m, n mod 2): about a
  // quarter of the coefficients. Two frequencies either way.
  EXPECT_LT(3 * (reduced_solve.solver.num_unknowns - 2), full_solve.solver.num_unknowns - 2);
  EXPECT_LT(MaxDifference(reduced_solve, full_solve), 1e-12);
  EXPECT_NEAR(reduced_solve.solution->frequencies()[0], full_solve.solution->frequencies()[0], 1e-13);
}

// Detected on the equations: the two reflections of the coupled pendulum
// (with every composition, the identity left out), and of a model forced by
// cos(theta_1) only the half-wave maps that turn theta_1.
TEST(HalfTurnSymmetry, DetectedOnTheEquations) {
  const examples::ExampleSetup e = examples::BuildExample("asym-pendulum");
  const std::vector<HalfTurnSymmetry> all = DetectHalfTurnSymmetries(e.problem.system, 2);
  // (h1, h2) free (autonomous), z -> -z, x -> -x alone: a group of 16.
  EXPECT_EQ(all.size(), 15u);
  EXPECT_EQ(SymmetriesOf(e.guess, all).size(), 2u);
  const examples::ExampleSetup f = examples::BuildExample("forced-vanderpol");
  for (const HalfTurnSymmetry& s : DetectHalfTurnSymmetries(f.problem.system, 2))
    if (s.sign[0] < 0) {
      EXPECT_EQ(s.half_turn[0], 1) << s.description;
    }
  EXPECT_EQ(SymmetriesOf(f.guess, DetectHalfTurnSymmetries(f.problem.system, 2)).size(), 1u);
  // A guess at rest has every symmetry trivially: none is imposed.
  EXPECT_TRUE(SymmetriesOf(HarmonicSolution(e.guess.basis(), e.guess.frequencies(),
                                            Eigen::MatrixXd::Zero(4, e.guess.basis().num_coefficients()),
                                            e.problem.system.variables()),
                           all)
                  .empty());
}

TEST(HalfTurnSymmetry, JacobianOfTheReducedProblemMatchesFiniteDifferences) {
  const examples::ExampleSetup e = examples::BuildExample("asym-pendulum");
  const HarmonicBasis basis = HarmonicBasis::Diamond(2, 3);
  const Sampling sampling = Sampling::Torus(SamplesForRule(e.problem.system, basis, SamplingRule::kRhb));
  const HarmonicBalanceProblem problem = WithSymmetries(e);  // the residual keeps a reference
  CollocationResidual r(problem, basis, sampling);
  EXPECT_LT(r.num_unknowns(), r.num_full_unknowns());
  const HarmonicSolution g = e.guess.OnBasis(basis);
  Eigen::VectorXd x = r.Pack(g.coefficients(), g.frequencies());
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  for (int i = 0; i < x.size(); ++i) x(i) += u(gen);
  Eigen::VectorXd F, Fp, Fm;
  Eigen::MatrixXd J;
  ASSERT_TRUE(r.Evaluate(x, &F, &J));
  ASSERT_EQ(J.rows(), r.num_residuals());
  ASSERT_EQ(J.cols(), r.num_unknowns());
  double worst = 0;
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp(i) += 1e-6;
    xm(i) -= 1e-6;
    r.Evaluate(xp, &Fp, nullptr);
    r.Evaluate(xm, &Fm, nullptr);
    worst = std::max(worst, ((Fp - Fm) / 2e-6 - J.col(i)).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-7);  // frequency columns included (the last two)
  // Pack and Unpack are inverse on the kept coefficients; dropped ones are zero.
  Eigen::MatrixXd coefficients;
  std::vector<double> w;
  r.Unpack(x, &coefficients, &w);
  EXPECT_EQ(r.Pack(coefficients, w), x);
  EXPECT_EQ(coefficients(0, 0), 0.0);  // x is odd: no constant
}

TEST(HalfTurnSymmetry, RefusesASystemWithoutTheSymmetry) {
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("v");
  s.AddEquation(s.D("x") - s.Var("v"));
  s.AddEquation(s.D("v") + s.Var("x") + s.Var("x") * s.Var("x") - Polynomial::Cos({1}, 1.0));
  const HalfTurnSymmetry odd{{1}, {-1, -1}, "x -> -x"};
  EXPECT_EQ(odd.EquationSign(s, 0, 1), -1);
  try {
    odd.EquationSign(s, 1, 1);
    ADD_FAILURE() << "x^2 is even";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("equation 2"), std::string::npos) << error.what();
  }
  HarmonicBalanceProblem problem{s, {1.0}, {false}, {}, {odd}};
  EXPECT_THROW(problem.Validate(), std::invalid_argument);
  EXPECT_THROW(HalfTurnSymmetry({{1, 0}, {-1, -1}, ""}).EquationSign(s, 0, 1), std::invalid_argument);
}

TEST(HarmonicSolution, ShiftedAdvancesTheAngles) {
  const examples::ExampleSetup e = examples::BuildExample("duffing-2tone");
  const HarmonicSolution& g = e.guess;
  const double t = 0.7;
  const std::vector<double> phase = {g.frequencies()[0] * t, g.frequencies()[1] * t};
  EXPECT_NEAR(g.Shifted(phase).Value(0, 0.0), g.Value(0, t), 1e-14);
  EXPECT_NEAR(g.Shifted(phase).Derivative(0, 0.3), g.Derivative(0, t + 0.3), 1e-14);
}

}  // namespace
}  // namespace rmhb

// Defaults only, on model files written for the purpose (not examples):
// every solve aims at the default accuracy target (1e-10) and what it
// reports as met is met against an independent reference -- the exact
// period by quadrature of the energy, a tight CVODE trajectory from the
// solution's own state (METHOD.md s.8).

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>

#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/branch.h"
#include "rmhb/pipeline/settings.h"
#include "rmhb/pipeline/solve.h"

namespace rmhb {
namespace {

SolveSummary SolveWithDefaults(const std::string& file, double* seconds = nullptr) {
  SolveSettings settings;
  settings.default_tol = SolveSettings::kDefaultTolerance;  // as rmhb solve
  const auto begin = std::chrono::steady_clock::now();
  const PreparedSolve prepared = PrepareSolve(LoadModel(file), settings);
  SolveOptions options;
  options.harmonic_balance = prepared.options;
  SolveSummary s = SolveModel(prepared.model, prepared.guess, options);
  if (seconds) *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return s;
}

// Period of x'' + V'(x) = 0 released at rest from b: 2 int_a^b dx / sqrt(2 (V(b) - V(x)))
// with V(a) = V(b), a < b; x = a + (b - a) sin^2(phi/2) makes the integrand
// smooth and even in phi, so the midpoint rule converges spectrally.
// `gap(e, d)` is V(e) - V(e + d), written without cancellation for small d
// (x itself is never formed near a turning point e: its rounding would be
// amplified there).
using Gap = std::function<double(double e, double d)>;
double ExactPeriod(const Gap& gap, double b) {
  double lo = -50, hi = 0;  // V(a) = V(b) on the other side of the minimum at 0
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (gap(b, mid - b) < 0 ? lo : hi) = mid;
  }
  const double a = 0.5 * (lo + hi);
  const int n = 4000;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double phi = M_PI * (i + 0.5) / n, s = std::sin(phi / 2), c = std::cos(phi / 2);
    const double g = phi < M_PI / 2 ? gap(a, (b - a) * s * s) : gap(b, -(b - a) * c * c);
    sum += (b - a) * s * c / std::sqrt(2 * g);
  }
  return 2 * sum * M_PI / n;
}

void ExpectTargetMet(const std::string& file, const Gap& gap, double A) {
  const SolveSummary s = SolveWithDefaults(file);
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  const HarmonicBalanceSummary& hb = s.harmonic_balance;
  EXPECT_EQ(hb.tolerance, 1e-10);
  ASSERT_TRUE(hb.estimate_calibrated);
  EXPECT_LE(hb.state_estimate, 1e-10);
  const double w = s.solution().frequencies()[0], exact = 2 * M_PI / ExactPeriod(gap, A);
  const double frequency_error = std::abs(w - exact) / exact;
  const integrators::ValidationReport v = ValidateOriginal(LoadModel(file), s.solution(), 2 * M_PI / w);
  ASSERT_TRUE(v.ok) << v.message;
  std::printf("  %s: N = %d (orders", file.c_str(), hb.order);
  for (int o : hb.orders_tried) std::printf(" %d", o);
  std::printf("), estimates state %.1e frequency %.1e; measured: frequency %.1e, orbit %.1e, %.1f ms\n",
              hb.state_estimate, hb.frequency_estimate, frequency_error, v.max_error / A, hb.seconds * 1e3);
  EXPECT_LE(frequency_error, 1e-10);
  EXPECT_LE(frequency_error, std::max(hb.frequency_estimate, 1e-13));  // an upper estimate (above round-off)
  EXPECT_LE(v.max_error / A, 1e-10);
}

// A model file prepared at a given order, and solved through SolveModel (the
// symmetries its guess has imposed) with CVODE's check over 20 periods.
PreparedSolve PreparedAtOrder(const std::string& file, int order, EquationsRoute route = EquationsRoute::kRecast) {
  SolveSettings settings;
  settings.order = order;
  settings.order_given = true;
  return PrepareSolve(LoadModel(file, {}, route), settings);
}
SolveSummary SolveAndValidate(const PreparedSolve& prepared) {
  SolveOptions options;
  options.harmonic_balance = prepared.options;
  options.validate = true;
  options.validate_periods = 20;
  return SolveModel(prepared.model, prepared.guess, options);
}

// A forced file (no conditions) whose equations are odd under x -> -x with
// t + T/2 gets that half-turn from its symmetric guess: half the unknowns,
// the full solve's answer, and CVODE's trajectory from the solution's own
// state. One with an even term, or with conditions (which a half-turn moves
// from t = 0 to T/2), gets none.
TEST(Symmetry, AForcedFileSolvesOnHalfTheUnknowns) {
  const PreparedSolve prepared = PreparedAtOrder("tests/pipeline/models/forced-quintic.yaml", 20);
  ASSERT_FALSE(prepared.model.invariances.empty());
  const SolveSummary s = SolveAndValidate(prepared);
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  ASSERT_EQ(s.symmetries.size(), 1u) << s.FullReport();
  ASSERT_TRUE(s.validation.has_value());
  EXPECT_LT(s.validation->verdict.relative_error, 1e-9) << s.FullReport();
  // The full problem from the same guess: the same solution, twice the unknowns.
  const HarmonicBalanceSummary full = SolveHarmonicBalance(prepared.model.problem, prepared.guess, prepared.options);
  ASSERT_TRUE(full.usable()) << full.FullReport();
  const HarmonicBalanceSummary& half = s.harmonic_balance;
  EXPECT_LE(2 * half.solver.num_unknowns, full.solver.num_unknowns + 1);
  EXPECT_LT((full.solution->coefficients() - half.solution->coefficients()).cwiseAbs().maxCoeff(), 1e-13);

  EXPECT_TRUE(LoadModel("tests/pipeline/models/quadratic-duffing.yaml").invariances.empty());
  // An odd autonomous oscillator released at rest, on the recast: no
  // half-turn, only time reversals (which keep t = 0 where it is).
  const Model autonomous = LoadModel("tests/pipeline/models/radical-oscillator.yaml");
  EXPECT_EQ(autonomous.equations, "recast");
  EXPECT_FALSE(autonomous.problem.conditions.empty());
  for (const HalfTurnSymmetry& s : autonomous.invariances) EXPECT_TRUE(s.reverses_time) << s.description;
}

// A start without the symmetry (the forced quintic's guess with 1e-2 of the
// second harmonic, as a simulated seed has the other parity's transient):
// Newton lands on the symmetric solution anyway, and order selection holds
// the higher orders to the symmetry the first solution has. The result is
// the full problem's at the order chosen, from the same start.
TEST(Symmetry, OrderSelectionHoldsHigherOrdersToTheFirstSolutionsSymmetry) {
  const PreparedSolve prepared = PrepareSolve(LoadModel("tests/pipeline/models/forced-quintic.yaml"), SolveSettings{});
  HarmonicBalanceOptions options = prepared.options;
  options.tolerance = 1e-10;  // the CLI's default target
  Eigen::MatrixXd c = prepared.guess.coefficients();
  c(0, 3) += 1e-2;  // x's cos 2 W t
  const HarmonicSolution asymmetric(prepared.guess.basis(), prepared.guess.frequencies(), c,
                                    prepared.model.problem.system.variables());
  ASSERT_TRUE(SymmetriesOf(asymmetric, prepared.model.invariances, {}).empty());
  const HarmonicBalanceSummary held = SolveHarmonicBalance(prepared.model.problem, asymmetric, options);
  ASSERT_TRUE(held.usable()) << held.FullReport();
  ASSERT_EQ(held.symmetries_found.size(), 1u) << held.FullReport();
  EXPECT_GE(held.orders_tried.size(), 2u) << held.FullReport();  // a higher order solved on the subspace

  HarmonicBalanceOptions fixed = options;
  fixed.tolerance = 0;  // one order, no selection: nothing imposed
  fixed.order = held.order;
  const HarmonicBalanceSummary full = SolveHarmonicBalance(prepared.model.problem, asymmetric.OnBasis(HarmonicBasis::Periodic(held.order)), fixed);
  ASSERT_TRUE(full.usable()) << full.FullReport();
  EXPECT_LE(2 * held.solver.num_unknowns, full.solver.num_unknowns + 1);
  EXPECT_LT((full.solution->coefficients() - held.solution->coefficients()).cwiseAbs().maxCoeff(), 1e-13);
}

// Solved through SolveModel (the symmetries the guess has imposed) and as
// the full problem from the same guess: the same solution.
struct ReducedAndFull {
  SolveSummary reduced;
  HarmonicBalanceSummary full;
};
ReducedAndFull SolveBothWays(const std::string& file, int order, EquationsRoute route) {
  const PreparedSolve prepared = PreparedAtOrder(file, order, route);
  return {SolveAndValidate(prepared), SolveHarmonicBalance(prepared.model.problem, prepared.guess, prepared.options)};
}

bool ReversesTime(const SolveSummary& s) {
  for (const std::string& d : s.symmetries)
    if (d.find("time reversal") != std::string::npos) return true;
  return false;
}

// A time reversal (t -> -t, z_j -> +-z_j) keeps t = 0 where it is, so it is
// imposed with conditions too: an oscillator launched from its centre is odd
// in t (sines only, x(0) = 0 dropped as met), a forced undamped one driven by
// a sine likewise. A quarter of the unknowns with the half-wave map, the
// full solve's solution, the exact period, CVODE's trajectory. The launched
// oscillator on its original equations (the reversal tested pointwise), the
// forced one on the recast (term by term).
TEST(Symmetry, TimeReversalsKeepSinesOrCosinesOnly) {
  const ReducedAndFull launched =
      SolveBothWays("tests/pipeline/models/launched-softening.yaml", 40, EquationsRoute::kAuto);
  EXPECT_EQ(launched.reduced.equations, "original");
  ASSERT_EQ(launched.reduced.status, SolveStatus::kConverged) << launched.reduced.FullReport();
  ASSERT_TRUE(launched.full.usable()) << launched.full.FullReport();
  EXPECT_TRUE(ReversesTime(launched.reduced)) << launched.reduced.FullReport();
  const HarmonicBalanceSummary& l = launched.reduced.harmonic_balance;
  EXPECT_EQ(l.solver.num_unknowns, 21);  // the sines of harmonics 1, 3, ..., 39 and w
  EXPECT_EQ(l.solver.num_residuals, 21);  // their balance and x'(0) = v
  EXPECT_GE(launched.full.solver.num_unknowns, 4 * (l.solver.num_unknowns - 1));
  const double v = 0.8, A = std::sqrt(std::expm1(v * v));
  const Gap gap = [](double e, double d) { return -0.5 * std::log1p(d * (2 * e + d) / (1 + e * e)); };
  const double exact = 2 * M_PI / ExactPeriod(gap, A);
  EXPECT_LT(std::abs(l.solution->frequencies()[0] - exact), 1e-12 * exact);
  EXPECT_LT(std::abs(launched.full.solution->frequencies()[0] - exact), 1e-12 * exact);
  EXPECT_LT((launched.full.solution->coefficients() - l.solution->coefficients()).cwiseAbs().maxCoeff(), 1e-12);
  ASSERT_TRUE(launched.reduced.validation.has_value());
  EXPECT_LT(launched.reduced.validation->verdict.relative_error, 1e-9);

  const ReducedAndFull forced = SolveBothWays("tests/pipeline/models/forced-undamped.yaml", 20, EquationsRoute::kAuto);
  EXPECT_EQ(forced.reduced.equations, "recast");
  ASSERT_EQ(forced.reduced.status, SolveStatus::kConverged) << forced.reduced.FullReport();
  ASSERT_TRUE(forced.full.usable()) << forced.full.FullReport();
  EXPECT_TRUE(ReversesTime(forced.reduced)) << forced.reduced.FullReport();
  const HarmonicBalanceSummary& f = forced.reduced.harmonic_balance;
  EXPECT_EQ(f.solver.num_unknowns, 10);  // the sines of harmonics 1, 3, ..., 19
  EXPECT_LT((forced.full.solution->coefficients() - f.solution->coefficients()).cwiseAbs().maxCoeff(), 1e-12);
  ASSERT_TRUE(forced.reduced.validation.has_value());
  EXPECT_LT(forced.reduced.validation->verdict.relative_error, 1e-9);

  // Damping breaks it.
  for (const HalfTurnSymmetry& s : LoadModel("tests/pipeline/models/forced-quintic.yaml").invariances)
    EXPECT_FALSE(s.reverses_time) << s.description;
}

// A forced file on the recast: its only conditions are the auxiliaries'
// pins, which hold at every t, so the half-turn is imposed with them; the
// pins of the flipped auxiliaries (tanh, sin: no constant term on the
// subspace) are implied and dropped, the cosine's is kept. The reduced
// solution solves the full problem (Newton on it stops at once) and
// CVODE's trajectory.
TEST(Symmetry, RecastPinsKeepTheHalfTurn) {
  const PreparedSolve prepared = PreparedAtOrder("tests/pipeline/models/forced-sine-tanh.yaml", 24);
  const HarmonicBalanceProblem& full = prepared.model.problem;
  ASSERT_EQ(full.conditions.size(), 3u);
  ASSERT_EQ(prepared.model.invariances.size(), 1u);
  const HalfTurnSymmetry& half_turn = prepared.model.invariances[0];
  EXPECT_FALSE(half_turn.reverses_time);
  std::vector<ConditionOnSubspace> kinds;
  for (const PointCondition& c : full.conditions) {
    ASSERT_GE(c.pinned_variable, 0) << c.description;
    kinds.push_back(ClassifyCondition(half_turn, c));
    EXPECT_EQ(kinds.back() == ConditionOnSubspace::kHolds, half_turn.sign[c.pinned_variable] < 0) << c.description;
  }
  EXPECT_EQ(std::count(kinds.begin(), kinds.end(), ConditionOnSubspace::kHolds), 2);

  const SolveSummary s = SolveAndValidate(prepared);
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  ASSERT_EQ(s.symmetries.size(), 1u) << s.FullReport();
  ASSERT_TRUE(s.validation.has_value());
  EXPECT_LT(s.validation->verdict.relative_error, 1e-9) << s.FullReport();
  const HarmonicBalanceSummary& reduced = s.harmonic_balance;
  const HarmonicBalanceSummary check = SolveHarmonicBalance(full, *reduced.solution, prepared.options);
  ASSERT_TRUE(check.usable()) << check.FullReport();
  EXPECT_LE(check.solver.iterations, 1) << check.FullReport();
  EXPECT_LE(2 * reduced.solver.num_unknowns, check.solver.num_unknowns + 1);
  EXPECT_LT((check.solution->coefficients() - reduced.solution->coefficients()).cwiseAbs().maxCoeff(), 1e-12);
}

// A forced file without a guess: rest fails, the settled simulated motion
// seeds the solve, and the half-turn its spectrum has (to 1e-9; 1e-12 is
// what the transient left) is imposed on that solve. The result solves the
// full problem and CVODE's trajectory.
TEST(Symmetry, ASettledStartKeepsItsSymmetry) {
  const PreparedSolve prepared = PreparedAtOrder("tests/pipeline/models/forced-pendulum.yaml", 25);
  const SolveSummary s = SolveAndValidate(prepared);
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  EXPECT_NE(s.start_route.find("simulation"), std::string::npos) << s.FullReport();
  EXPECT_TRUE(s.symmetries.empty());  // the guess (rest) says nothing
  const HarmonicBalanceSummary& reduced = s.harmonic_balance;
  ASSERT_EQ(reduced.symmetries_found.size(), 1u) << s.FullReport();
  EXPECT_EQ(reduced.solver.num_unknowns, 77) << s.FullReport();
  ASSERT_TRUE(s.validation.has_value());
  EXPECT_LT(s.validation->verdict.relative_error, 1e-9) << s.FullReport();
  const HarmonicBalanceSummary check = SolveHarmonicBalance(prepared.model.problem, *reduced.solution, prepared.options);
  ASSERT_TRUE(check.usable()) << check.FullReport();
  EXPECT_LE(check.solver.iterations, 1) << check.FullReport();
  EXPECT_EQ(check.solver.num_unknowns, 153);
  // 1/cond(J) ~ 1e-6 here: round-off moves a Newton step's result by ~1e-12.
  EXPECT_LT((check.solution->coefficients() - reduced.solution->coefficients()).cwiseAbs().maxCoeff(), 1e-10);
}

// A continuation started with a target holds its branch to the symmetries
// the first solution has only where the equations keep them along the
// range: at a = 0 the half-turn holds, a x^2 breaks it (held anyway, the
// trace stopped at once: "no tangent at the start"). The end point is the
// direct solve's at a = 0.6, with its even harmonics.
TEST(Symmetry, ABranchIsHeldOnlyToSymmetriesKeptAlongTheRange) {
  const PreparedSolve p = PreparedAtOrder("tests/pipeline/models/symmetry-breaking-parameter.yaml", 25);
  ContinueOptions o;
  o.parameter = "a";
  o.from = 0;
  o.to = 0.6;
  o.max_step = 0.2;
  o.harmonic_balance = p.options;
  o.harmonic_balance.tolerance = 1e-8;
  const BranchSummary b = ContinueModel(p.model, p.guess, o);
  ASSERT_EQ(b.status, BranchStatus::kCompleted) << b.FullReport();
  const ContinuationPoint& last = b.continuation.points.back();
  ASSERT_NEAR(last.parameter, 0.6, 1e-12);
  EXPECT_GT(std::abs(last.solution.coefficients()(0, 3)), 1e-3);  // x's cos 2 W t
  HarmonicBalanceOptions fixed = p.options;
  fixed.tolerance = 0;
  fixed.order = last.solution.basis().order();
  const HarmonicBalanceSummary direct =
      SolveHarmonicBalance(WithParameters(p.model, {{"a", 0.6}}).problem, last.solution, fixed);
  ASSERT_TRUE(direct.usable()) << direct.FullReport();
  EXPECT_LE(direct.solver.iterations, 1);
  EXPECT_LT((direct.solution->coefficients() - last.solution.coefficients()).cwiseAbs().maxCoeff(), 1e-10);
}

// What a condition at t = 0 is on a reversal's subspace: x(0) is zero where
// x is odd, x'(0) where it is even.
TEST(Symmetry, ConditionsOnATimeReversalsSubspace) {
  HalfTurnSymmetry even{{0}, {1}, "x even"}, odd{{0}, {-1}, "x odd"}, half_wave{{1}, {-1}, "half-wave"};
  even.reverses_time = odd.reverses_time = true;
  EXPECT_EQ(ClassifyCondition(even, PointCondition::Value(0, 1.5)), ConditionOnSubspace::kKept);
  EXPECT_EQ(ClassifyCondition(even, PointCondition::DerivativeValue(0, 0)), ConditionOnSubspace::kHolds);
  EXPECT_EQ(ClassifyCondition(even, PointCondition::DerivativeValue(0, 0.8)), ConditionOnSubspace::kViolated);
  EXPECT_EQ(ClassifyCondition(odd, PointCondition::Value(0, 0)), ConditionOnSubspace::kHolds);
  EXPECT_EQ(ClassifyCondition(odd, PointCondition::Value(0, 1.5)), ConditionOnSubspace::kViolated);
  EXPECT_EQ(ClassifyCondition(odd, PointCondition::DerivativeValue(0, 0.8)), ConditionOnSubspace::kKept);
  EXPECT_EQ(ClassifyCondition(half_wave, PointCondition::Value(0, 0)), ConditionOnSubspace::kKept);
  // A model whose condition the guess's reversal would violate does not get it:
  // the launched oscillator with a cosine guess (even) and x'(0) = v.
  Model model = LoadModel("tests/pipeline/models/launched-softening.yaml", {}, EquationsRoute::kOriginal);
  const HarmonicSolution guess = GuessAtOrder(model, 10);
  HarmonicSolution cosine = guess;
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(guess.coefficients().rows(), guess.coefficients().cols());
  c(0, 1) = 1;  // x = cos(w t), x' = -w sin(w t): even x
  c(1, 2) = -guess.frequencies()[0];
  cosine = HarmonicSolution(guess.basis(), guess.frequencies(), c, guess.variables());
  EXPECT_EQ(ImposeGuessSymmetries(cosine, &model), 1);  // the half-wave map only
  ASSERT_EQ(model.problem.symmetries.size(), 1u);
  EXPECT_FALSE(model.problem.symmetries[0].reverses_time);
}

TEST(DefaultTarget, PeriodicModelsMeetItAgainstTheExactPeriod) {
  // V = e^x - 1 - x: V(e) - V(e + d) = -e^e expm1(d) + d.
  ExpectTargetMet("tests/pipeline/models/exp-oscillator.yaml",
                  [](double e, double d) { return d - std::exp(e) * std::expm1(d); }, 2);
  // V = sqrt(1 + x^2) - 1: V(e) - V(e + d) = -d (2e + d) / (sqrt(1 + e^2) + sqrt(1 + (e + d)^2)).
  ExpectTargetMet("tests/pipeline/models/radical-oscillator.yaml",
                  [](double e, double d) {
                    return -d * (2 * e + d) / (std::sqrt(1 + e * e) + std::sqrt(1 + (e + d) * (e + d)));
                  },
                  3);
}

// Quasi-periodic: the index set is chosen from the coefficients (adaptive
// enrichment), the symmetries detected on the equations, the start found by
// identification when the file gives no guess.
void ExpectTorusWithin(const std::string& file, double t_end, double tolerance) {
  double seconds = 0;
  const SolveSummary s = SolveWithDefaults(file, &seconds);
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  const HarmonicBalanceSummary& hb = s.harmonic_balance;
  EXPECT_LE(hb.truncation_estimate, 1e-10);
  const integrators::ValidationReport v = ValidateOriginal(LoadModel(file), s.solution(), t_end, 4001);
  ASSERT_TRUE(v.ok) << v.message;
  std::printf("  %s: %d harmonics (%s), start %s, %zu symmetries, estimate %.1e; max error %.2e over [0, %g]; "
              "%.2f s with the start\n",
              file.c_str(), s.solution().basis().size(), s.solution().basis().shape().c_str(), s.start_route.c_str(),
              s.symmetries.size(), hb.truncation_estimate, v.max_error, t_end, seconds);
  EXPECT_LT(v.max_error, tolerance);
}

TEST(DefaultTarget, QuasiPeriodicModelsWithinTheirTrajectories) {
  ExpectTorusWithin("tests/pipeline/models/coupled-pendula.yaml", 1000, 1e-8);
  ExpectTorusWithin("tests/pipeline/models/my-forced-vdp.yaml", 1000, 1e-8);
}

TEST(DefaultTarget, TheAsymmetricPendulumFileOverTwoThousandTimeUnits) {
  ExpectTorusWithin("examples/models/asym-pendulum.yaml", 2000, 1e-8);
}

}  // namespace
}  // namespace rmhb

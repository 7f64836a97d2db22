// Continuation on model files with stability at every point and its
// bifurcations, against brute-force references that use no harmonic
// balance: the periodic orbit found by shooting on the original equations
// (Newton on phi_T(y) - y with the CVODE monodromy matrix), its multipliers,
// and the parameter where one crosses the unit circle found by the secant
// method on those multipliers. Model files written for these tests
// (tests/pipeline/models), defaults only.

#include "rmhb/pipeline/monodromy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "integrators/cvode_integrator.h"
#include "integrators/floquet.h"
#include "rmhb/branch_switching.h"
#include "rmhb/hill_stability.h"
#include "rmhb/pipeline/start.h"
#include "tests/pipeline/shooting.h"

namespace rmhb {
namespace {

using testing::Orbit;
using testing::ReferenceCrossing;
using testing::Shoot;

constexpr const char* kQuadratic = "tests/pipeline/models/quadratic-duffing.yaml";
constexpr const char* kSelfExcited = "tests/pipeline/models/forced-self-excited.yaml";

ContinuationProblem ProblemOn(const char* file, const std::string& parameter, double start, double end) {
  return ModelContinuationProblem([file, parameter](double v) { return LoadModel(file, {{parameter, v}}); },
                                  parameter, start, end);
}

std::vector<BifurcationPoint> OfType(const ContinuationSummary& s, BifurcationType type) {
  std::vector<BifurcationPoint> out;
  for (const BifurcationPoint& b : s.bifurcations)
    if (b.type == type) out.push_back(b);
  return out;
}

// The model's default order; the continuation's defaults otherwise, but for
// the largest step: arclength in (coefficients, w), where the coefficients
// move far more than w near a resonance.
ContinuationSummary TraceModel(const char* file, double start, double end, ContinuationOptions options = {}) {
  const Model model = LoadModel(file, {{"w", start}});
  options.harmonic_balance.order = model.default_order;
  options.max_step = 0.2;
  return TraceBranch(ProblemOn(file, "w", start, end), GuessAtOrder(model, model.default_order), options);
}

TEST(BranchBifurcations, PeriodDoublingsOfTheQuadraticOscillatorAtTheShootingReferenceByEveryMethod) {
  const Model model = LoadModel(kQuadratic);
  double first = 0, second = 0;  // the reference, computed once
  for (StabilityMethod method :
       {StabilityMethod::kMonodromy, StabilityMethod::kHill, StabilityMethod::kHarmonicMonodromy}) {
    ContinuationOptions options;
    options.stability_method = method;
    const ContinuationSummary s = TraceModel(kQuadratic, 2.5, 1.5, options);
    ASSERT_TRUE(s.completed()) << s.FullReport();
    const std::vector<BifurcationPoint> pd = OfType(s, BifurcationType::kPeriodDoubling);
    ASSERT_EQ(pd.size(), 2u) << s.FullReport();
    EXPECT_EQ(s.bifurcations.size(), 2u) << s.FullReport();  // nothing else on this branch
    for (const ContinuationPoint& p : s.points) EXPECT_EQ(p.stability_method, method);
    // Unstable exactly between the two: the period-T orbit is a saddle there.
    for (const ContinuationPoint& p : s.points) {
      if (p.bifurcation >= 0) continue;
      const bool between = p.parameter < pd[0].parameter && p.parameter > pd[1].parameter;
      EXPECT_EQ(p.stability == PointStability::kUnstable, between) << p.parameter;
    }
    if (first == 0) {
      // The secant starts 0.005 either side of the located value (inside the
      // range where the critical multiplier is real) and converges on its own.
      Eigen::VectorXd y = model.state(s.points.front().solution, 0.0);
      first = ReferenceCrossing(model, pd[0].parameter + 5e-3, pd[0].parameter - 5e-3, true, &y);
      second = ReferenceCrossing(model, pd[1].parameter + 5e-3, pd[1].parameter - 5e-3, true, &y);
    }
    for (int i = 0; i < 2; ++i) {
      EXPECT_TRUE(pd[i].located) << pd[i].Describe("w");
      EXPECT_LE(std::abs(pd[i].distance), 1e-8);
      EXPECT_NEAR(pd[i].multiplier.real(), -1, 1e-8);
      EXPECT_EQ(pd[i].method, ToString(method));
      EXPECT_NEAR(pd[i].parameter, i == 0 ? first : second, 1e-8) << pd[i].Describe("w");
      char error[32];
      std::snprintf(error, sizeof error, "%.2e", pd[i].parameter - (i == 0 ? first : second));
      ::testing::Test::RecordProperty(std::string(ToString(method)) + "_pd" + std::to_string(i) + "_error", error);
    }
  }
}

// The point of a branch farthest from the period-T orbit: the largest odd
// harmonics (on the base w/2).
const ContinuationPoint& MostDoubled(const ContinuationSummary& branch) {
  const ContinuationPoint* best = &branch.points.front();
  double largest = 0;
  for (const ContinuationPoint& p : branch.points) {
    double odd = 0;
    for (int i = 1; i < p.solution.basis().size(); ++i)
      if (p.solution.basis().harmonic(i)[0] % 2) odd += p.solution.coefficients().middleCols(2 * i - 1, 2).squaredNorm();
    if (odd > largest) largest = odd, best = &p;
  }
  return *best;
}

TEST(BranchSwitching, ThePeriodDoubledBranchIsAnOrbitOfPeriodTwoTBetweenBothDoublings) {
  const Model model = LoadModel(kQuadratic);
  ContinuationOptions options;
  options.harmonic_balance.order = model.default_order;
  const ContinuationProblem problem = ProblemOn(kQuadratic, "w", 2.5, 1.5);
  const ContinuationSummary s = TraceBranch(problem, GuessAtOrder(model, model.default_order), options);
  const std::vector<BifurcationPoint> pd = OfType(s, BifurcationType::kPeriodDoubling);
  ASSERT_EQ(pd.size(), 2u) << s.FullReport();
  const DoubledBranch d = TraceDoubledBranch(problem, s, pd[0], options);
  ASSERT_TRUE(d.started) << d.message;
  EXPECT_LT(d.critical_mode_residual, 1e-8);
  const ContinuationSummary& b = *d.branch;
  EXPECT_EQ(b.order, 2 * model.default_order);
  // It leaves the first doubling and merges back at the second.
  ASSERT_EQ(b.status, ContinuationStatus::kStopped) << b.FullReport();
  double nearest = HUGE_VAL;
  for (const ContinuationPoint& p : b.points) nearest = std::min(nearest, std::abs(p.parameter - pd[1].parameter));
  EXPECT_LT(nearest, 1e-7) << b.FullReport();
  for (const ContinuationPoint& p : b.points) EXPECT_NE(p.stability_method, StabilityMethod::kNone);

  // Its most doubled point: an orbit of the original equations of period 2T
  // and not T (shooting over 2T from its state stays there; over T it does
  // not close), with the shooting orbit's multipliers.
  const ContinuationPoint& p = MostDoubled(b);
  const double w = 2 * p.solution.frequencies()[0];
  const Eigen::VectorXd y = model.state(p.solution, 0.0);
  const Orbit twice = Shoot(model, w, y, 2);
  EXPECT_LT((twice.y - y).cwiseAbs().maxCoeff(), 1e-8 * y.cwiseAbs().maxCoeff());
  const integrators::IntegrationResult once = integrators::IntegrateOde(model.original({w}), y, 0.0, {2 * M_PI / w});
  EXPECT_GT((once.trajectory.states.row(0).transpose() - y).norm(), 1e-2);
  double largest = 0;
  for (const auto& m : twice.mu) largest = std::max(largest, std::abs(m));
  EXPECT_NEAR(p.max_multiplier, largest, 1e-7);
}

// Every orbit of a conservative oscillator is neutral (a double multiplier
// 1). At order 80 near b = 1 the truncated orbit moves the non-trivial
// multiplier off 1 by more than the 1e-6 band (1.00000154 at b = 0.975, was
// called unstable from there on), but by less than ten times the orbit's
// own estimated error, which now widens the band (NeutralBand).
TEST(BranchStabilityVerdicts, ATruncatedConservativeBranchStaysNeutral) {
  const char* file = "tests/pipeline/models/relativistic-launch.yaml";
  const Model model = LoadModel(file, {{"b", 0.97}});
  ContinuationOptions options;
  options.harmonic_balance.order = 80;
  options.stability_method = StabilityMethod::kMonodromy;
  options.max_step = 0.1;  // the arclength is mostly the amplitude's (2.5 -> 3.5): range / 10 took 416 steps
  const ContinuationSummary s = TraceBranch(ProblemOn(file, "b", 0.97, 0.99), GuessAtOrder(model, 80), options);
  ASSERT_TRUE(s.completed()) << s.FullReport();
  int beyond_fixed_band = 0;
  for (const ContinuationPoint& p : s.points) {
    EXPECT_EQ(p.stability, PointStability::kNeutral) << "b = " << p.parameter << ", max|mu| " << p.max_multiplier;
    EXPECT_LE(std::abs(p.max_multiplier - 1), p.neutral_band) << p.parameter;
    beyond_fixed_band += std::abs(p.max_multiplier - 1) > options.neutral_band;
  }
  EXPECT_GT(beyond_fixed_band, 3);
}

TEST(BranchBifurcations, NeimarkSackerOfAForcedSelfExcitedOscillatorAtTheShootingReference) {
  const ContinuationSummary s = TraceModel(kSelfExcited, 1.1, 1.2);
  ASSERT_TRUE(s.completed()) << s.FullReport();
  ASSERT_EQ(s.bifurcations.size(), 1u) << s.FullReport();
  const BifurcationPoint& ns = s.bifurcations[0];
  ASSERT_EQ(ns.type, BifurcationType::kNeimarkSacker);
  EXPECT_TRUE(ns.located);
  const Model model = LoadModel(kSelfExcited);
  Eigen::VectorXd y = model.state(s.points.front().solution, 0.0);
  const double reference = ReferenceCrossing(model, ns.parameter - 5e-3, ns.parameter + 5e-3, false, &y);
  EXPECT_NEAR(ns.parameter, reference, 1e-8) << ns.Describe("w");
  // The new frequency from the critical multiplier's angle.
  const Orbit at = Shoot(model, reference, y);
  double angle = 0;
  for (const auto& m : at.mu) angle = std::max(angle, std::arg(m));
  EXPECT_NEAR(ns.torus_frequency, reference * angle / (2 * M_PI), 1e-7);
  char error[32];
  std::snprintf(error, sizeof error, "%.2e", ns.parameter - reference);
  ::testing::Test::RecordProperty("ns_error", error);
}

TEST(BranchSwitching, TheTorusJustPastTheNeimarkSackerPointIsATrueQuasiPeriodicOrbit) {
  const Model model = LoadModel(kSelfExcited, {{"w", 1.1}});
  ContinuationOptions options;
  options.harmonic_balance.order = model.default_order;
  options.max_step = 0.2;
  const ContinuationProblem problem = ProblemOn(kSelfExcited, "w", 1.1, 1.2);
  const ContinuationSummary s = TraceBranch(problem, GuessAtOrder(model, model.default_order), options);
  ASSERT_EQ(s.bifurcations.size(), 1u) << s.FullReport();
  const TorusStart t = TorusFromNeimarkSacker(problem, s, s.bifurcations[0], options);
  ASSERT_TRUE(t.solved) << t.message;
  EXPECT_LT(t.critical_mode_residual, 1e-8);
  EXPECT_LT(t.residual, 1e-12);
  // Just past the point, where the periodic orbit is unstable (supercritical).
  EXPECT_GT(t.parameter, t.bifurcation_parameter);
  EXPECT_LT(t.parameter - t.bifurcation_parameter, 1e-3);
  EXPECT_EQ(t.periodic_side, "unstable");
  ASSERT_EQ(t.torus->frequencies().size(), 2u);
  EXPECT_EQ(t.torus->frequencies()[0], t.parameter);
  EXPECT_NEAR(t.torus->frequencies()[1], t.w2_at_bifurcation, 1e-3);
  EXPECT_GT(t.theta2_amplitude, 1e-2);
  // A trajectory of the original equations from the torus' state follows
  // the torus over 20 periods of the forcing.
  const Model there = LoadModel(kSelfExcited, {{"w", t.parameter}});
  const double t_end = 20 * 2 * M_PI / t.parameter;
  const integrators::ValidationReport v = ValidateTorus(there, *t.torus, t_end);
  ASSERT_TRUE(v.ok) << v.message;
  const ValidationVerdict verdict = JudgeValidation(there, *t.torus, v, t_end, 1e-8);
  EXPECT_TRUE(verdict.ok) << verdict.Describe();
  // What torus continuation starts from.
  ASSERT_TRUE(t.problem && t.sampling && t.phase_reference);
  EXPECT_EQ(t.problem->num_unknown_frequencies(), 1);
}

TEST(BranchStability, ATwoDofBranchAtOrder25GetsTheLinearisationsMonodromyAtEveryPointAgreeingWithHill) {
  constexpr const char* kChain = "tests/pipeline/models/forced-chain.yaml";
  const Model model = LoadModel(kChain, {{"W", 1.3}});
  ContinuationOptions options;
  options.harmonic_balance.order = model.default_order;  // 25: 204 unknowns, over Hill's 200
  const ContinuationProblem problem = ModelContinuationProblem(
      [](double W) { return LoadModel(kChain, {{"W", W}}); }, "W", 1.3, 1.6);
  const ContinuationSummary s = TraceBranch(problem, GuessAtOrder(model, model.default_order), options);
  ASSERT_TRUE(s.completed()) << s.FullReport();
  EXPECT_TRUE(s.stability_note.empty()) << s.stability_note;
  // An ODE without auxiliaries: the harmonic balance linearisation's own
  // monodromy (rmhb/harmonic_monodromy.h) at every point, cross-checked at
  // the first against the CVODE monodromy (Hill's 204 unknowns are over the
  // cross-check's 200).
  EXPECT_GE(s.harmonic_monodromy_points, static_cast<int>(s.points.size()));
  EXPECT_EQ(s.hill_points, 0);
  EXPECT_EQ(s.monodromy_points, 0);
  EXPECT_NE(s.stability_cross_check.find("monodromy"), std::string::npos) << s.stability_cross_check;
  for (size_t i = 0; i < s.points.size(); i += s.points.size() / 2) {
    const ContinuationPoint& p = s.points[i];
    EXPECT_EQ(p.stability_method, StabilityMethod::kHarmonicMonodromy);
    const HillStabilityReport hill = HillStability(LoadModel(kChain, {{"W", p.parameter}}).problem, p.solution);
    ASSERT_EQ(hill.multipliers.size(), p.multipliers.size());
    for (const auto& mu : hill.multipliers) {
      double nearest = HUGE_VAL;
      for (const auto& m : p.multipliers) nearest = std::min(nearest, std::abs(m - mu));
      EXPECT_LT(nearest, 1e-7) << "W = " << p.parameter;
    }
  }
}

TEST(BranchStability, PinnedAuxiliariesAndADaeGetMultipliersAtEveryPoint) {
  // The pendulum's sin/cos are pinned: Hill's method does not apply.
  constexpr const char* kPendulum = "tests/pipeline/models/forced-pendulum.yaml";
  const Model pendulum = LoadModel(kPendulum, {{"W", 0.7}});
  ContinuationOptions options;
  options.harmonic_balance.order = 30;
  const StartedSolve start = SolveFromAnyStart(pendulum, GuessAtOrder(pendulum, 30), options.harmonic_balance);
  ASSERT_TRUE(start.summary.usable()) << start.note;
  const ContinuationSummary s = TraceBranch(
      ModelContinuationProblem([](double W) { return LoadModel(kPendulum, {{"W", W}}); }, "W", 0.7, 0.9),
      *start.summary.solution, options);
  ASSERT_TRUE(s.completed()) << s.FullReport();
  for (const ContinuationPoint& p : s.points) ASSERT_EQ(p.stability_method, StabilityMethod::kMonodromy);
  const ContinuationPoint& last = s.points.back();
  const Orbit orbit = Shoot(pendulum, last.parameter, pendulum.state(last.solution, 0.0));
  double largest = 0;
  for (const auto& m : orbit.mu) largest = std::max(largest, std::abs(m));
  EXPECT_NEAR(last.max_multiplier, largest, 1e-8);

  // A DAE: the IDA monodromy against Hill's method at the first point.
  constexpr const char* kDae = "tests/pipeline/models/forced-softening-dae.yaml";
  const Model dae = LoadModel(kDae);
  options.harmonic_balance.order = dae.default_order;
  const ContinuationSummary d = TraceBranch(
      ModelContinuationProblem([](double w) { return LoadModel(kDae, {{"w", w}}); }, "w", 0.6, 0.8),
      GuessAtOrder(dae, dae.default_order), options);
  for (const ContinuationPoint& p : d.points) ASSERT_NE(p.stability_method, StabilityMethod::kNone);
  EXPECT_NE(d.stability_cross_check.find("agree to"), std::string::npos) << d.stability_cross_check;
  const MonodromyResult ida = ModelMonodromy(dae, d.points.front().solution);
  const HillStabilityReport hill = HillStability(dae.problem, d.points.front().solution);
  ASSERT_TRUE(ida.ok) << ida.message;
  ASSERT_EQ(ida.multipliers.size(), hill.multipliers.size());
  for (const auto& mu : hill.multipliers) {
    double nearest = HUGE_VAL;
    for (const auto& m : ida.multipliers) nearest = std::min(nearest, std::abs(m - mu));
    EXPECT_LT(nearest, 1e-7);
  }
}

}  // namespace
}  // namespace rmhb

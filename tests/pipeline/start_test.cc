// Model files with no guess, defaults only: a forced 1-DOF and a forced
// 2-DOF model swept through their resonances, the forced damped pendulum;
// every solution a true orbit (a CVODE integration from its own state stays
// within 1e-8 over a period), whichever start got there.

#include "rmhb/pipeline/start.h"

#include "rmhb/pipeline/analyze.h"
#include "rmhb/pipeline/branch.h"
#include "rmhb/pipeline/settings.h"
#include "rmhb/pipeline/solve.h"
#include "tests/pipeline/shooting.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>

namespace rmhb {
namespace {

struct Sweep {
  const char* file;
  std::vector<double> frequencies;
  int order;
};

void ExpectTrueOrbits(const Sweep& sweep, int* simulated) {
  for (double W : sweep.frequencies) {
    const Model model = LoadModel(sweep.file, {{"W", W}});
    HarmonicBalanceOptions options;
    options.order = sweep.order;
    const StartedSolve s = SolveFromAnyStart(model, GuessAtOrder(model, sweep.order), options);
    ASSERT_TRUE(s.summary.usable()) << sweep.file << " W = " << W << ": " << s.note;
    const integrators::ValidationReport v = ValidateOriginal(model, *s.summary.solution, 2 * M_PI / W);
    ASSERT_TRUE(v.ok) << v.message;
    EXPECT_LT(v.max_error, 1e-8) << sweep.file << " W = " << W << " (start: " << s.route << ")";
    *simulated += s.route != "guess";
  }
}

TEST(Start, ForcedOneAndTwoDofModelsConvergeThroughResonanceWithoutAGuess) {
  int simulated = 0;
  ExpectTrueOrbits({"tests/pipeline/models/forced-duffing.yaml",
                    {0.6, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.5, 1.8, 2.2}, 15}, &simulated);
  ExpectTrueOrbits({"tests/pipeline/models/forced-chain.yaml",
                    {0.6, 0.9, 1.0, 1.05, 1.1, 1.2, 1.5, 1.7, 1.8, 1.9, 2.2}, 15}, &simulated);
  // Near the resonances the guess (rest) is not enough: the simulated start
  // did the work there (otherwise this test would not test it).
  EXPECT_GE(simulated, 3);
}

TEST(Start, TheForcedDampedPendulumConvergesWithDefaults) {
  int simulated = 0;
  ExpectTrueOrbits({"tests/pipeline/models/forced-pendulum.yaml", {0.7, 0.8, 0.9, 1.0}, 30}, &simulated);
  EXPECT_GE(simulated, 3);
}

TEST(Start, SaysWhyWhenNothingWorks) {
  Model model = LoadModel("tests/pipeline/models/forced-duffing.yaml", {{"W", 1.2}});
  HarmonicBalanceOptions options;
  options.order = 15;
  options.solver.max_iterations = 1;
  options.order_continuation = false;
  StartOptions start;
  start.max_periods = 50;  // too short to settle: damping 0.05
  const StartedSolve s = SolveFromAnyStart(model, GuessAtOrder(model, 15), options, start);
  EXPECT_FALSE(s.summary.usable());
  EXPECT_GT(s.summary.solver.final_residual, 1e-6);
  EXPECT_NE(s.note.find("did not settle within 50 periods"), std::string::npos) << s.note;
  EXPECT_THROW(SolveFromAnyStart(model, GuessAtOrder(model, 15), options, StartOptions{0, 10, 1}), std::invalid_argument);
}

// The forced pendulum at W = 0.8 from rest (no guess): the zero start fails
// at order 25, and at 2x (here capped at 50) too; raise_order_on_failure
// decides whether the second is tried. The automatic start, which now
// tries the settled motion before the raised orders (a change of cost, not
// of result, here), ends on the settled motion, a true orbit.
TEST(Start, AForcedGuessIsNotRaisedBeforeTheSettledMotionIsTried) {
  const Model model = LoadModel("tests/pipeline/models/forced-pendulum.yaml");
  HarmonicBalanceOptions options;
  options.order = 25;
  options.tolerance = 1e-10;
  options.soft_tolerance = true;
  options.max_order = 50;
  const HarmonicSolution guess = GuessAtOrder(model, 25);
  const HarmonicBalanceSummary raised = SolveHarmonicBalance(model.problem, guess, options);
  EXPECT_FALSE(raised.converged());
  EXPECT_EQ(raised.orders_tried, (std::vector<int>{25, 50}));
  HarmonicBalanceOptions once = options;
  once.raise_order_on_failure = false;
  EXPECT_EQ(SolveHarmonicBalance(model.problem, guess, once).orders_tried, (std::vector<int>{25}));

  const StartedSolve s = SolveFromAnyStart(model, guess, options);
  ASSERT_TRUE(s.summary.usable()) << s.note;
  EXPECT_EQ(s.route.rfind("simulation", 0), 0u) << s.route;
  EXPECT_EQ(s.note.find("raised orders"), std::string::npos) << s.note;  // the last resort was not needed
  const integrators::ValidationReport v = ValidateOriginal(model, *s.summary.solution, 2 * M_PI / 0.8);
  ASSERT_TRUE(v.ok) << v.message;
  EXPECT_LT(v.max_error, 1e-8);
}

}  // namespace
}  // namespace rmhb

namespace rmhb {
namespace {

// analyze decides its transient: a lightly damped forced model file is
// recorded once its stroboscopic state has settled, with no --transient.
TEST(Start, AnalyzeWaitsForALightlyDampedMotionToSettle) {
  const Model model = LoadModel("tests/pipeline/models/forced-duffing.yaml", {{"c", 0.02}});
  AnalyzeOptions options;
  options.solve.order = 20;
  const AnalyzeSummary a = Analyze(model, options);
  ASSERT_TRUE(a.ok()) << a.FullReport();
  EXPECT_GT(a.trajectory->settle_periods, 100);  // damping 0.02: a slow transient
  EXPECT_LT(a.validation->max_error, 1e-8);
}

}  // namespace
}  // namespace rmhb

namespace rmhb {
namespace {

// An autonomous model file with neither guess nor initial state starts at
// rest, an equilibrium of its equations: Newton from there converges to it
// at once (non-physical: no oscillation), and a record from it stays there.
// The identification records from rest + kRestPerturbation instead and
// finds the self-excited orbit. Reference: Van der Pol's period at the same
// mu (y = x' of Rayleigh's oscillator obeys Van der Pol's equation), solved
// from the bundled example's own guess.
TEST(Start, ASelfExcitedModelWithoutAnyStartLeavesItsRest) {
  const Model model = LoadModel("tests/pipeline/models/rayleigh-from-rest.yaml");
  double perturbation = -1;
  EXPECT_EQ(RecordStart(model, &perturbation), Eigen::VectorXd::Constant(2, kRestPerturbation));
  EXPECT_EQ(perturbation, kRestPerturbation);
  HarmonicBalanceOptions options;
  options.order = 40;
  const StartedSolve s = SolveFromAnyStart(model, GuessAtOrder(model, 40), options);
  ASSERT_TRUE(s.summary.usable()) << s.note;
  EXPECT_NE(s.route.find("the start is an equilibrium"), std::string::npos) << s.route;
  EXPECT_NE(s.note.find("equilibrium"), std::string::npos) << s.note;  // why the guess was left

  const Model vdp = LoadModel("examples/models/vanderpol.yaml", {{"eps", 1.5}});
  const HarmonicBalanceSummary reference = SolveHarmonicBalance(vdp.problem, GuessAtOrder(vdp, 40), options);
  ASSERT_TRUE(reference.usable());
  const double w = s.summary.solution->frequencies()[0], w_vdp = reference.solution->frequencies()[0];
  EXPECT_NEAR(w, w_vdp, 1e-11 * w_vdp);
  const integrators::ValidationReport v = ValidateOriginal(model, *s.summary.solution, 2 * M_PI / w);
  ASSERT_TRUE(v.ok) << v.message;
  EXPECT_LT(v.max_error, 1e-8);
}

// No orbit to find: a damped oscillator's perturbed rest decays back, and
// the start says so rather than calling the equilibrium an orbit. A forced
// model's rest is not an equilibrium (its forcing moves it), an initial
// state off rest is kept as the user gave it.
TEST(Start, OnlyAnEquilibriumStartIsPerturbed) {
  const Model damped = LoadModel("tests/pipeline/models/damped-at-rest.yaml");
  HarmonicBalanceOptions options;
  options.order = 15;
  const StartedSolve s = SolveFromAnyStart(damped, GuessAtOrder(damped, 15), options);
  EXPECT_FALSE(s.summary.usable());
  EXPECT_NE(s.note.find("from identification"), std::string::npos) << s.note;

  double perturbation = -1;
  const Model forced = LoadModel("tests/pipeline/models/forced-duffing.yaml");
  ASSERT_EQ(forced.initial_state.cwiseAbs().maxCoeff(), 0.0);  // rest, but forced
  EXPECT_EQ(RecordStart(forced, &perturbation), forced.initial_state);
  EXPECT_EQ(perturbation, 0.0);
  const Model vdp = LoadModel("examples/models/vanderpol.yaml");
  EXPECT_EQ(RecordStart(vdp, &perturbation), vdp.initial_state);
  EXPECT_EQ(perturbation, 0.0);
}

}  // namespace
}  // namespace rmhb

namespace rmhb {
namespace {

// The recast's auxiliary of a steep tanh(10 x') fails from every start, the
// equations as written do not: SolveModel falls back on them (and says so)
// rather than ending not converged. Reference: CVODE from the solution's own
// state (order 100: the kink-like term's truncation is ~6e-6 there). With
// tanh(10 x') the recast now converges from the settled record, sampled
// densely enough since RecordUnaliased (2.6e-6 from CVODE at order 60).
TEST(Start, ARecastThatReachesNoSolutionFallsBackOnTheOriginalEquations) {
  SolveSettings settings;
  settings.default_tol = SolveSettings::kDefaultTolerance;  // as rmhb solve
  settings.order = 100;
  settings.order_given = true;
  const PreparedSolve prepared = PrepareSolve(LoadModel("tests/pipeline/models/steep-friction.yaml"), settings);
  ASSERT_EQ(prepared.model.equations, "recast");
  ASSERT_TRUE(prepared.model.original_equations);
  SolveOptions options;
  options.harmonic_balance = prepared.options;
  options.validate = true;
  options.validate_tolerance = 1e-5;
  const SolveSummary s = SolveModel(prepared.model, prepared.guess, options);
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  EXPECT_EQ(s.equations, "original");
  EXPECT_NE(s.start_route.find("on the original equations"), std::string::npos) << s.start_route;
  EXPECT_NE(s.start_note.find("the recast reached no physical solution"), std::string::npos) << s.start_note;
  ASSERT_TRUE(s.validation && s.validation->report.ok);
  EXPECT_LT(s.validation->verdict.relative_error, 1e-5);

  options.auto_start = false;  // the guess only: no fallback either
  EXPECT_EQ(SolveModel(prepared.model, prepared.guess, options).equations, "recast");
}

}  // namespace
}  // namespace rmhb

namespace rmhb {
namespace {

// A model solved as `rmhb solve FILE --validate [--stability]` solves it:
// the default tolerance, the automatic start.
SolveSummary SolveAsTheCli(const Model& model, bool stability = false) {
  SolveSettings settings;
  settings.default_tol = SolveSettings::kDefaultTolerance;
  const PreparedSolve prepared = PrepareSolve(model, settings);
  SolveOptions options;
  options.harmonic_balance = prepared.options;
  options.validate = true;
  options.stability = stability;
  return SolveModel(prepared.model, prepared.guess, options);
}

// Two motions of x'' + c x' + x = F1 cos W1 t + F2 cos W2 t differ by the
// homogeneous solution d from d(0) = d'(0) = 0.1 (the second starts 0.1 off
// rest in both states), and the forced response is known in closed form:
// TorusSettleTime must return the first whole slowest period at which
// max(|d|, |d'|) <= 1e-9 max(1, |x|, |x'|).
TEST(Start, TwoMotionsOfAForcedTorusMeetWhenTheHomogeneousPartHasDecayed) {
  const Model model = LoadModel("tests/pipeline/models/two-tone-linear.yaml");
  ASSERT_EQ(model.initial_state, Eigen::VectorXd::Zero(2));
  int periods = 0;
  const double settled = TorusSettleTime(model, StartOptions{}, &periods);
  const double c = 0.2, a = c / 2, w = std::sqrt(1 - a * a), d0 = 0.1, b = (d0 + a * d0) / w;
  const double F[2] = {0.5, 0.3}, W[2] = {0.6, 0.848528137423857}, T = 2 * M_PI / W[0];
  auto gap = [&](double t) {
    const double e = std::exp(-a * t);
    const double d = e * (d0 * std::cos(w * t) + b * std::sin(w * t));
    const double dv = e * ((b * w - a * d0) * std::cos(w * t) - (d0 * w + a * b) * std::sin(w * t));
    return std::max(std::abs(d), std::abs(dv));
  };
  auto scale = [&](double t) {
    double x = 0, v = 0;
    for (int i = 0; i < 2; ++i) {
      const std::complex<double> z(1 - W[i] * W[i], c * W[i]);
      const double amplitude = F[i] / std::abs(z), phase = std::arg(z);
      x += amplitude * std::cos(W[i] * t - phase);
      v -= amplitude * W[i] * std::sin(W[i] * t - phase);
    }
    return std::max({1.0, std::abs(x), std::abs(v)});
  };
  EXPECT_DOUBLE_EQ(settled, periods * T);
  EXPECT_LE(gap(settled), 1.05e-9 * scale(settled));
  EXPECT_GT(gap(settled - T), 0.95e-9 * scale(settled - T));
  for (int k = 1; k < periods - 1; ++k) EXPECT_GT(gap(k * T), 0.95e-9 * scale(k * T)) << k;
}

// The same with defaults on a Duffing oscillator: recorded only after its
// transient has decayed (the default tenth of the record left e^-5 of it,
// and the identification failed), identified on the known bases, solved and
// checked against CVODE.
// Parametric excitation: the default guess (rest) converges to x = 0, a
// true solution but an unstable one (h = 0.4 > 2c); the motion from rest +
// 0.1 settles on the orbit that moves, which replaces it. Checked: CVODE
// from its own state, and its multipliers (CVODE's monodromy) inside the
// unit circle. With h = 0.1 rest is stable and stays the answer.
TEST(Start, AConstantSolutionOfAParametricModelGivesWayToTheOrbitItsMotionSettlesOn) {
  const SolveSummary s = SolveAsTheCli(LoadModel("tests/pipeline/models/parametric-duffing.yaml"), true);
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  EXPECT_NE(s.start_route.find("simulation"), std::string::npos) << s.start_route;
  EXPECT_NE(s.start_note.find("constant in time"), std::string::npos) << s.start_note;
  EXPECT_GT(s.solution().Amplitude(0), 0.1);
  ASSERT_TRUE(s.validation && s.validation->report.ok);
  EXPECT_LT(s.validation->verdict.relative_error, 1e-8);
  ASSERT_TRUE(s.stability && s.stability->floquet);
  for (const auto& mu : s.stability->floquet->multipliers) EXPECT_LT(std::abs(mu), 1 - 1e-3);

  const SolveSummary rest = SolveAsTheCli(LoadModel("tests/pipeline/models/parametric-duffing.yaml", {{"h", 0.1}}), true);
  ASSERT_EQ(rest.status, SolveStatus::kConverged) << rest.FullReport();
  EXPECT_EQ(rest.start_route, "guess");
  EXPECT_LT(rest.solution().Amplitude(0), 1e-12);
  ASSERT_TRUE(rest.stability);
  EXPECT_EQ(rest.stability->verdict, StabilityVerdict::kStable);
}

// Nothing but the equations: the frequency's guess from the trajectory from
// the file's start (rest, which is not this model's equilibrium), the orbit
// by the automatic start. Its period against CVODE's between upward
// crossings of u = 0 from the same start, and the solution against CVODE
// from its own state. Such a file was refused (missing 'frequencies'); the
// same equations moved to put the equilibrium at rest start next to it.
TEST(Start, AnAutonomousFileWithNothingButItsEquationsFindsItsLimitCycle) {
  const Model model = LoadModel("tests/pipeline/models/fitzhugh-nagumo.yaml");
  EXPECT_NE(model.frequency_note.find("the trajectory from initial_state, period"), std::string::npos)
      << model.frequency_note;
  const SolveSummary s = SolveAsTheCli(model);
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  ASSERT_TRUE(s.validation && s.validation->report.ok);
  EXPECT_LT(s.validation->verdict.relative_error, 1e-8);
  const double period = testing::LimitCyclePeriodOf(model, 4000);
  EXPECT_NEAR(2 * M_PI / s.solution().frequencies()[0], period, 1e-8 * period);

  // Van der Pol-Duffing written without frequencies or initial_state: rest is
  // its equilibrium, and the trajectory starts 0.1 off it.
  const Model at_rest = LoadModel("tests/pipeline/models/vdp-duffing-bare.yaml");
  EXPECT_NE(at_rest.frequency_note.find("+ 0.1 (an equilibrium)"), std::string::npos) << at_rest.frequency_note;
  const SolveSummary v = SolveAsTheCli(at_rest);
  ASSERT_EQ(v.status, SolveStatus::kConverged) << v.FullReport();
  ASSERT_TRUE(v.validation && v.validation->report.ok);
  EXPECT_LT(v.validation->verdict.relative_error, 1e-8);
  Model next_to_rest = at_rest;
  next_to_rest.initial_state.array() += kRestPerturbation;
  const double vdp_period = testing::LimitCyclePeriodOf(next_to_rest);
  EXPECT_NEAR(2 * M_PI / v.solution().frequencies()[0], vdp_period, 1e-8 * vdp_period);
}

// A self-excited motion still approaching its cycle when the default
// transient ends: the record once its returns to a section have settled
// (before, the record's slow growth defeated the identification, analyze
// stopped with identification_failed and solve kept the equilibrium its
// guess converged to). Reference: CVODE's period between upward crossings
// of z = 0 over 1000 time units from the same start.
TEST(Start, ASlowlySettlingSelfExcitedMotionIsRecordedOnItsCycle) {
  const Model model = LoadModel("tests/pipeline/models/slow-vdp-duffing.yaml");
  const double period = testing::LimitCyclePeriodOf(model, 1000);
  SolveSettings settings;  // as `rmhb analyze` with no options
  settings.default_tol = SolveSettings::kDefaultTolerance;
  const PreparedSolve prepared = PrepareSolve(model, settings);
  AnalyzeOptions options;
  options.solve = prepared.options;
  const AnalyzeSummary a = Analyze(prepared.model, options);
  ASSERT_TRUE(a.ok()) << a.FullReport();
  EXPECT_GT(a.trajectory->settle_periods, 0);
  EXPECT_GT(a.trajectory->record.transient, 0.1 * (a.trajectory->record.t_end - a.trajectory->record.transient));
  EXPECT_NEAR(2 * M_PI / a.solve->solution->frequencies()[0], period, 1e-8 * period);
  EXPECT_LT(a.validation->max_error, 1e-8);

  const SolveSummary s = SolveAsTheCli(model);
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  EXPECT_EQ(s.start_route, "identification");
  ASSERT_TRUE(s.validation && s.validation->report.ok);
  EXPECT_LT(s.validation->verdict.relative_error, 1e-8);
  EXPECT_NEAR(2 * M_PI / s.solution().frequencies()[0], period, 1e-8 * period);
}

TEST(Start, AForcedTorusWithoutAGuessIsRecordedOnceItHasSettled) {
  const SolveSummary s = SolveAsTheCli(LoadModel("tests/pipeline/models/two-tone-duffing.yaml"));
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  EXPECT_EQ(s.start_route, "identification");
  EXPECT_EQ(s.solution().frequencies(), (std::vector<double>{1.3, 2.61}));
  ASSERT_TRUE(s.validation && s.validation->report.ok);
  EXPECT_LT(s.validation->verdict.relative_error, 1e-8);
}

}  // namespace
}  // namespace rmhb

namespace rmhb {
namespace {

// A continuation whose first point fails on the recast traces the branch on
// the original equations (as SolveModel); at the model's default order, as
// `rmhb solve --continue` without --order. Every point is checked against
// CVODE from its own state (N = 25: truncation ~1e-3 on this kink-like term;
// a point off the branch would be O(0.1) off).
TEST(Start, AContinuationWhoseRecastFailsAtTheStartRunsOnTheOriginalEquations) {
  SolveSettings settings;
  const PreparedSolve p = PrepareSolve(LoadModel("tests/pipeline/models/steep-friction.yaml"), settings);
  ContinueOptions o;
  o.parameter = "W";
  o.from = 0.6;
  o.to = 0.7;
  o.harmonic_balance = p.options;
  const BranchSummary b = ContinueModel(p.model, p.guess, o);
  ASSERT_EQ(b.status, BranchStatus::kCompleted) << b.FullReport();
  EXPECT_NE(b.start_route.find("on the original equations"), std::string::npos) << b.start_route;
  ASSERT_GE(b.continuation.points.size(), 3u);
  const Model original = p.model.original_equations();
  for (const ContinuationPoint& point : b.continuation.points) {
    const Model here = WithParameters(original, {{"W", point.parameter}});
    const integrators::ValidationReport v = ValidateOriginal(here, point.solution, 2 * M_PI / point.parameter);
    ASSERT_TRUE(v.ok) << v.message;
    EXPECT_LT(v.max_error, 2e-3) << "W = " << point.parameter;
  }
}

}  // namespace
}  // namespace rmhb

// The pipeline as a program calls it: a model file written for the test,
// loaded, analyzed (integrate, identify, seed, solve, validate) and checked
// against an independent reference, the limit-cycle period CVODE measures
// between upward zero crossings.

#include "rmhb/pipeline/analyze.h"
#include "rmhb/pipeline/stability.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "rmhb/model/model_error.h"
#include "tests/pipeline/shooting.h"

namespace rmhb {
namespace {

const char* kModel = "tests/pipeline/models/quintic-rayleigh.yaml";

TEST(Pipeline, AnalyzeFindsTheLimitCycleOfAModelFileWithDefaults) {
  const Model model = LoadModel(kModel);
  AnalyzeOptions options;
  options.solve.order = 30;
  const AnalyzeSummary s = Analyze(model, options);
  ASSERT_TRUE(s.ok()) << s.FullReport();
  ASSERT_TRUE(s.identification && s.seed && s.validation);
  EXPECT_LT(s.validation->max_error, 1e-8) << s.FullReport();
  const double w = s.solve->solution->frequencies()[0];

  const double period = testing::LimitCyclePeriodOf(model);
  EXPECT_NEAR(2 * M_PI / w, period, 1e-9 * period) << s.FullReport();
  // The identified frequency seeded Newton close by.
  EXPECT_NEAR(s.seed->frequencies[0], w, 1e-8);
}

// Without identification the model's own guess starts the solve. This file
// has none: the default is the harmonic through initial_state, q(0) cos(w t)
// (model_definition.cc, DefaultGuesses), which reaches the limit cycle the
// identified start finds. A zero start finds the equilibrium, which the
// summary calls non-physical, never a solution; a program's own guess works.
TEST(Pipeline, WithoutIdentificationTheModelsGuessStartsTheSolve) {
  Model model = LoadModel(kModel);
  AnalyzeOptions options;
  options.identify = false;
  options.solve.order = 30;
  const AnalyzeSummary by_default = Analyze(model, options);
  EXPECT_FALSE(by_default.trajectory.has_value());
  ASSERT_TRUE(by_default.ok()) << by_default.FullReport();

  const AnalyzeSummary identified = Analyze(model, AnalyzeOptions{options.solve});
  ASSERT_TRUE(identified.ok()) << identified.FullReport();
  EXPECT_NEAR(by_default.solve->solution->frequencies()[0], identified.solve->solution->frequencies()[0], 1e-13);

  const HarmonicSolution& cycle = *identified.solve->solution;
  const HarmonicSolution origin(cycle.basis(), cycle.frequencies(),
                                Eigen::MatrixXd::Zero(cycle.num_variables(), cycle.basis().num_coefficients()),
                                cycle.variables());
  model.guess = [&](int) { return origin; };
  const AnalyzeSummary zero = Analyze(model, options);
  EXPECT_EQ(zero.status, AnalyzeStatus::kNonPhysical);
  EXPECT_NE(zero.message.find("equilibrium"), std::string::npos) << zero.message;
  EXPECT_FALSE(zero.validation.has_value());

  const HarmonicSolution near = identified.solve->solution->WithFrequencies({1.05 * identified.solve->solution->frequencies()[0]});
  model.guess = [&](int) { return near; };
  const AnalyzeSummary guessed = Analyze(model, options);
  ASSERT_TRUE(guessed.ok()) << guessed.FullReport();
  EXPECT_LT(guessed.validation->max_error, 1e-8);
  EXPECT_NEAR(guessed.solve->solution->frequencies()[0], identified.solve->solution->frequencies()[0], 1e-13);

  options.solve.solver.max_iterations = 1;
  options.solve.order_continuation = false;
  const AnalyzeSummary starved = Analyze(model, options);
  EXPECT_EQ(starved.status, AnalyzeStatus::kNotConverged);
  EXPECT_GT(starved.solve->solver.final_residual, 1e-10);
  EXPECT_FALSE(starved.validation.has_value());
}

TEST(Pipeline, MisuseThrows) {
  EXPECT_THROW(LoadModel(kModel, {{"nope", 1}}), model::ModelError);
  EXPECT_THROW(LoadModel("tests/pipeline/models/missing.yaml"), model::ModelError);
  AnalyzeOptions bad;
  bad.validate_periods = 0;
  EXPECT_THROW(Analyze(LoadModel(kModel), bad), std::invalid_argument);
  Model blind = LoadModel(kModel);
  blind.original = nullptr;
  blind.original_error = "none here";
  try {
    Analyze(blind, {});
    ADD_FAILURE() << "a model without original equations was analyzed";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("none here"), std::string::npos);
  }
}

}  // namespace
}  // namespace rmhb

namespace rmhb {
namespace {

// The model's solution at `order` from its own guess.
HarmonicSolution SolvedAt(const Model& model, int order) {
  HarmonicBalanceOptions options;
  options.order = order;
  const HarmonicBalanceSummary solved = SolveHarmonicBalance(model.problem, GuessAtOrder(model, order), options);
  if (!solved.usable()) throw std::runtime_error(solved.FullReport());
  return *solved.solution;
}

// Hill's method and the CVODE monodromy matrix, two independent routes to
// the same multipliers, on a forced model file written for the tests.
TEST(PipelineStability, HillAndTheMonodromyMatrixAgree) {
  const Model model = LoadModel("tests/sweep/models/hardening.yaml", {{"W", 1.2}});
  const HarmonicSolution solved = SolvedAt(model, 20);
  const StabilitySummary s = Stability(model, solved);
  ASSERT_TRUE(s.hill && s.floquet && s.floquet->ok) << s.hill_note << s.floquet_note;
  ASSERT_TRUE(s.max_multiplier_difference.has_value());
  EXPECT_LT(*s.max_multiplier_difference, 1e-8);
  EXPECT_TRUE(s.agree());
  EXPECT_EQ(s.verdict, StabilityVerdict::kStable);  // the only response below the bistable band
  // Damping 2 zeta = 0.08 over a period 2 pi / W: |mu| = exp(-0.04 T) exactly.
  for (const auto& mu : s.floquet->multipliers) EXPECT_NEAR(std::abs(mu), std::exp(-0.04 * 2 * M_PI / 1.2), 1e-9);
  StabilityOptions wrong;
  wrong.neutral_band = 2.0;
  EXPECT_THROW(Stability(model, solved, wrong), std::invalid_argument);
}

// Every orbit of a conservative system is neutral: its multipliers are a
// double 1 (exactly; the period depends on the energy). A truncated orbit
// (order 8 at amplitude 3: ~1e-5 off) splits CVODE's pair into 1.009 and
// 0.991, which was judged "unstable" by the larger alone; their product,
// which the error moves only to first order, is 1 (det = 1: div f = 0).
TEST(PipelineStability, AConservativeOrbitIsNeutralAtALowOrder) {
  const Model model = LoadModel("tests/pipeline/models/conservative-duffing.yaml");
  const StabilitySummary s = Stability(model, SolvedAt(model, 8));
  ASSERT_TRUE(s.floquet && s.floquet->ok) << s.floquet_note;
  ASSERT_EQ(s.floquet->multipliers.size(), 2u);
  const double split = std::abs(std::abs(s.floquet->multipliers[0]) - 1);
  EXPECT_GT(split, 1e-4);  // the truncation's split, far outside the band
  EXPECT_NEAR(std::abs(s.floquet->multipliers[0] * s.floquet->multipliers[1]), 1, 1e-8);
  EXPECT_EQ(s.floquet_verdict, StabilityVerdict::kNeutral);
  EXPECT_EQ(s.verdict, StabilityVerdict::kNeutral);
  EXPECT_NEAR(s.largest_modulus, 1, 1e-8);
  EXPECT_NE(s.judged_by.find("geometric mean"), std::string::npos) << s.judged_by;
}

}  // namespace
}  // namespace rmhb

// The physical check (rmhb/definition_check.h, HarmonicBalanceSummary::physical):
// physical solutions of every bundled model pass by a wide margin; a wrong
// root of the recast, an aliased HDHB solution and a collapsed frequency are
// flagged.

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "examples/example_system.h"
#include "rmhb/definition_check.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/model/recast.h"

namespace rmhb {
namespace {

std::string ModelPath(const std::string& name) {
  return std::string(RMHB_SOURCE_DIR) + "/examples/models/" + name + ".yaml";
}

HarmonicBalanceSummary Solve(const HarmonicBalanceProblem& problem, const HarmonicSolution& guess,
                             int order, SolverMethod method = SolverMethod::kAuto,
                             SamplingRule rule = SamplingRule::kRhb,
                             Scaling scaling = Scaling::kEquilibrate) {
  HarmonicBalanceOptions o;
  o.order = order;
  o.solver.method = method;
  o.solver.scaling = scaling;
  o.rule = rule;
  return SolveHarmonicBalance(problem, guess, o);
}

// Converged alias-free solutions at adequate order meet their definitions to
// round-off between the samples (measured 1e-15 .. 1e-11), far below the 1e-6
// floor; the check costs a fraction of the solve.
TEST(DefinitionCheck, PhysicalSolutionsOfTheBundledExamplesPass) {
  struct Case {
    std::string name;
    int order;
  };
  for (const Case& c : std::vector<Case>{{"pendulum", 25}, {"relativistic", 55}, {"rayleigh-plesset", 30}}) {
    SCOPED_TRACE(c.name);
    examples::ExampleSetup e = examples::BuildExample(c.name);
    HarmonicBalanceSummary s = Solve(e.problem, e.guess, c.order);
    ASSERT_TRUE(s.converged());
    ASSERT_TRUE(s.definition_check.has_value());
    EXPECT_TRUE(s.physical) << s.non_physical;
    EXPECT_LT(s.definition_check->error, 1e-10);
    EXPECT_GE(s.definition_check->points, 4 * s.samples[0]);
  }
  // Duffing has no auxiliaries: nothing to check, still physical.
  examples::ExampleSetup duffing = examples::BuildExample("duffing");
  HarmonicBalanceSummary s = Solve(duffing.problem, duffing.guess, 20);
  EXPECT_TRUE(s.usable());
  EXPECT_FALSE(s.definition_check.has_value());
}

TEST(DefinitionCheck, PhysicalSolutionsOfTheBundledModelFilesPass) {
  for (std::string name : {"pendulum", "relativistic", "rayleigh-plesset"}) {
    SCOPED_TRACE(name);
    model::RecastResult r = model::Recast(model::LoadModelFile(ModelPath(name)));
    const int order = r.problem.frequencies.size() == 1 ? 40 : 7;
    HarmonicBalanceSummary s = Solve(r.problem, r.InitialGuess(order), order);
    ASSERT_TRUE(s.converged());
    ASSERT_TRUE(s.definition_check.has_value());
    EXPECT_TRUE(s.physical) << s.non_physical;
    EXPECT_LT(s.definition_check->error, 1e-8);
  }
  // No auxiliaries (every variable a state): nothing to compare, still checked
  // for a collapsed frequency.
  for (std::string name : {"duffing", "vanderpol", "softening-dae", "forced-vanderpol"}) {
    SCOPED_TRACE(name);
    model::RecastResult r = model::Recast(model::LoadModelFile(ModelPath(name)));
    const int order = r.problem.frequencies.size() == 1 ? 25 : 5;
    HarmonicBalanceSummary s = Solve(r.problem, r.InitialGuess(order), order);
    EXPECT_TRUE(s.usable()) << s.FullReport();
    EXPECT_FALSE(s.definition_check.has_value());
  }
}

// u^2 + v^2 - 1 = 0 also holds for u = -sqrt(1 - v^2). At beta = 0.99
// unscaled Tikhonov (and L-M) from the default guess converge to such a
// branch, with a residual at round-off and a frequency 3 % off; Newton finds
// the physical one (and so does equilibrated Tikhonov: the check is what is
// tested here, on a branch some solver does reach).
TEST(DefinitionCheck, WrongRootOfTheSqrtRecastIsFlagged) {
  examples::ExampleSetup e = examples::BuildExample("relativistic", {{"beta", 0.99}});
  HarmonicBalanceSummary wrong = Solve(e.problem, e.guess, 64, SolverMethod::kTikhonov, SamplingRule::kRhb, Scaling::kNone);
  ASSERT_TRUE(wrong.converged()) << wrong.FullReport();
  EXPECT_FALSE(wrong.physical);
  EXPECT_FALSE(wrong.usable());
  ASSERT_TRUE(wrong.definition_check.has_value());
  EXPECT_EQ(wrong.definition_check->worst_variable, "u");
  EXPECT_GT(wrong.definition_check->error, 0.1);
  // It is the other root: u < 0 where the check found the discrepancy.
  EXPECT_LT(wrong.solution->Value(2, wrong.definition_check->worst_time), 0);
  EXPECT_NE(wrong.FullReport().find("NON-PHYSICAL"), std::string::npos);

  HarmonicBalanceSummary right = Solve(e.problem, e.guess, 64, SolverMethod::kNewton);
  ASSERT_TRUE(right.converged());
  EXPECT_TRUE(right.physical) << right.non_physical;
  EXPECT_NEAR(right.solution->frequencies()[0], e.reference.frequency, 1e-3);

  // The deliberately flipped root of the physical solution: off by 2 |u|.
  Eigen::MatrixXd c = right.solution->coefficients();
  c.row(2) *= -1;
  const HarmonicSolution flipped(right.solution->basis(), right.solution->frequencies(), c,
                                 right.solution->variables());
  const DefinitionCheck check = CheckDefinitions(flipped, e.problem.definitions, right.samples);
  EXPECT_FALSE(check.physical);
  EXPECT_EQ(check.worst_variable, "u");
  EXPECT_NEAR(check.error, 2.0, 1e-4);
}

// HDHB (M = 2N + 1, aliased) at beta = 0.95, N = 16 converges to a solution
// 5 % off the true frequency whose u is 56 % off sqrt(1 - v^2) between the
// samples; HDHB at N = 24 and RHB at N = 16 are within their truncation.
TEST(DefinitionCheck, AliasedHdhbSolutionIsFlagged) {
  examples::ExampleSetup e = examples::BuildExample("relativistic", {{"beta", 0.95}});
  HarmonicBalanceSummary hdhb = Solve(e.problem, e.guess, 16, SolverMethod::kAuto, SamplingRule::kHdhb);
  ASSERT_TRUE(hdhb.converged());
  EXPECT_FALSE(hdhb.alias_free);
  EXPECT_FALSE(hdhb.physical);
  EXPECT_GT(std::abs(hdhb.solution->frequencies()[0] - e.reference.frequency), 0.02);
  EXPECT_GT(hdhb.definition_check->error, 3 * hdhb.definition_check->tolerance);
  for (auto [order, rule] : {std::pair{24, SamplingRule::kHdhb}, std::pair{16, SamplingRule::kRhb}}) {
    HarmonicBalanceSummary s = Solve(e.problem, e.guess, order, SolverMethod::kAuto, rule);
    ASSERT_TRUE(s.converged());
    EXPECT_TRUE(s.physical) << s.non_physical;
    EXPECT_LT(std::abs(s.solution->frequencies()[0] - e.reference.frequency), 1e-2);
  }
}

// A negative unknown frequency is no oscillation (HDHB N = 4 reaches w < 0).
TEST(DefinitionCheck, NonPositiveFrequencyIsFlagged) {
  examples::ExampleSetup e = examples::BuildExample("relativistic", {{"beta", 0.95}});
  HarmonicBalanceSummary s = Solve(e.problem, e.guess, 4, SolverMethod::kAuto, SamplingRule::kHdhb);
  ASSERT_TRUE(s.converged());
  ASSERT_LE(s.solution->frequencies()[0], 0);
  EXPECT_FALSE(s.physical);
  EXPECT_NE(s.non_physical.find("unknown frequency w1"), std::string::npos) << s.non_physical;
}

// x = 0 solves Van der Pol at every frequency: from a zero start the solve
// "converges" at once, and the unknown frequency means nothing.
TEST(DefinitionCheck, EquilibriumWithAnUnknownFrequencyIsFlagged) {
  examples::ExampleSetup e = examples::BuildExample("vanderpol");
  const HarmonicSolution zero(e.guess.basis(), e.guess.frequencies(),
                              Eigen::MatrixXd::Zero(e.guess.coefficients().rows(), e.guess.coefficients().cols()),
                              e.problem.system.variables());
  HarmonicBalanceSummary s = Solve(e.problem, zero, e.guess.basis().order(), SolverMethod::kNewton);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  EXPECT_FALSE(s.physical);
  EXPECT_NE(s.non_physical.find("an equilibrium"), std::string::npos) << s.non_physical;
  // The limit cycle from the example's own guess is an oscillation.
  HarmonicBalanceSummary cycle = Solve(e.problem, e.guess, e.guess.basis().order());
  ASSERT_TRUE(cycle.converged()) << cycle.FullReport();
  EXPECT_TRUE(cycle.physical) << cycle.non_physical;
}

TEST(DefinitionCheck, TimeDerivativeMatchesTheSolutionsDerivative) {
  examples::ExampleSetup e = examples::BuildExample("pendulum");
  const HarmonicSolution d = TimeDerivative(e.guess, 1);
  for (double t : {0.0, 0.3, 1.7})
    EXPECT_NEAR(d.Value(0, t), e.guess.Derivative(0, t), 1e-14);
}

TEST(DefinitionCheck, RejectsBadOptions) {
  examples::ExampleSetup e = examples::BuildExample("pendulum");
  DefinitionCheckOptions o;
  o.oversampling = 1;
  EXPECT_THROW(CheckDefinitions(e.guess, e.problem.definitions, {}, o), std::invalid_argument);
  EXPECT_THROW(CheckDefinitions(e.guess, VariableDefinitions{}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb

// A model file solved through the automatic recast must give the same answer
// as the hand-written C++ system of the same example (different variables,
// different auxiliaries, same physics): frequency and the user variable's
// harmonics to 1e-13.

#include <cstdio>

#include <gtest/gtest.h>

#include "examples/example_system.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/model/model_definition.h"
#include "rmhb/model/recast.h"

namespace rmhb {
namespace {

struct Case {
  std::string name;
  std::map<std::string, double> parameters;
  int order;
};

class ModelVersusExample : public ::testing::TestWithParam<Case> {};

TEST_P(ModelVersusExample, SameSolution) {
  const Case& c = GetParam();
  const model::RecastResult recast =
      model::Recast(model::LoadModelFile("examples/models/" + c.name + ".yaml"), c.parameters);
  const examples::ExampleSetup example = examples::BuildExample(c.name, c.parameters);
  HarmonicBalanceOptions o;
  o.order = c.order;
  const HarmonicBalanceSummary from_file =
      SolveHarmonicBalance(recast.problem, recast.InitialGuess(c.order), o);
  const HarmonicBalanceSummary by_hand = SolveHarmonicBalance(example.problem, example.guess, o);
  ASSERT_TRUE(from_file.converged()) << from_file.FullReport();
  ASSERT_TRUE(by_hand.converged()) << by_hand.FullReport();
  EXPECT_NEAR(from_file.solution->frequencies()[0], by_hand.solution->frequencies()[0], 1e-13);
  // Variable 0 is the user's variable in both.
  const Eigen::VectorXd a = from_file.solution->coefficients().row(0);
  const Eigen::VectorXd b = by_hand.solution->coefficients().row(0);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-13);
}

INSTANTIATE_TEST_SUITE_P(
    PaperSystems, ModelVersusExample,
    ::testing::Values(Case{"pendulum", {{"theta0", 1.5}}, 25},
                      Case{"relativistic", {{"beta", 0.85}}, 55},
                      Case{"vanderpol", {{"eps", 1.0}}, 40},
                      Case{"duffing", {{"c", 0.1}, {"k", 1.0}, {"a", 1.0}, {"F", 1.0}, {"w", 1.5}}, 20},
                      Case{"rayleigh-plesset", {}, 30}),
    [](const ::testing::TestParamInfo<Case>& info) {
      std::string n = info.param.name;
      for (char& ch : n)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return n;
    });

// Quasi-periodic: the file model (base w1 = w known, w2 unknown, x'(0) = 0,
// a one-line guess) against the C++ example on the same diamond: the same
// torus. (Both take the same automatic path in rmhb solve: the adaptive
// index set and the detected symmetry, tests/cli.)
TEST(ModelVersusExample, ForcedVanDerPolQuasiPeriodic) {
  const model::RecastResult recast =
      model::Recast(model::LoadModelFile("examples/models/forced-vanderpol.yaml"));
  const examples::ExampleSetup example = examples::BuildExample("forced-vanderpol");
  ASSERT_EQ(recast.problem.frequencies.size(), 2u);
  EXPECT_EQ(recast.problem.unknown_frequency, example.problem.unknown_frequency);
  HarmonicBalanceOptions o;
  o.order = 12;
  const HarmonicBalanceSummary from_file = SolveHarmonicBalance(recast.problem, recast.InitialGuess(o.order), o);
  const HarmonicBalanceSummary by_hand = SolveHarmonicBalance(example.problem, example.guess, o);
  ASSERT_TRUE(from_file.converged()) << from_file.FullReport();
  ASSERT_TRUE(by_hand.converged()) << by_hand.FullReport();
  const std::vector<double>& w_file = from_file.solution->frequencies();
  const std::vector<double>& w_hand = by_hand.solution->frequencies();
  EXPECT_EQ(w_file[0], 2.3);
  EXPECT_NEAR(w_file[1], 0.99746625, 1e-8);  // the simulated value
  EXPECT_NEAR(w_file[1], w_hand[1], 1e-13);
  const Eigen::VectorXd a = from_file.solution->coefficients().row(0);
  const Eigen::VectorXd b = by_hand.solution->coefficients().row(0);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-12);
  std::printf("  forced-vanderpol p 12: |d w2| %.1e, max |d coefficient| %.1e\n",
              std::abs(w_file[1] - w_hand[1]), (a - b).cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace rmhb

// Harmonic balance on the original equations (rmhb/pipeline/model.h,
// EquationsRoute; METHOD.md s.13), on model files written for these tests:
// the pendulum against its exact frequency, the forced damped pendulum
// against an alias-free recast solve at twice the order, the automatic choice
// and the half-wave symmetry imposed from a symmetric guess.

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/model.h"

namespace rmhb {
namespace {

// pi / (2 K(m)) by the arithmetic-geometric mean: K(m) = pi / (2 AGM(1, sqrt(1 - m))).
double PendulumFrequency(double amplitude) {
  const double m = std::pow(std::sin(amplitude / 2), 2);
  long double a = 1, b = std::sqrt(1.0L - m);
  for (int i = 0; i < 20; ++i) {
    const long double next = (a + b) / 2;
    b = std::sqrt(a * b);
    a = next;
  }
  return static_cast<double>(a);  // pi / (2 K) = AGM(1, sqrt(1 - m))
}

HarmonicBalanceSummary Solve(Model* model, int order, bool impose = true, int* imposed = nullptr) {
  HarmonicBalanceOptions options;
  options.order = order;
  const HarmonicSolution guess = GuessAtOrder(*model, order);
  const int n = impose ? ImposeGuessSymmetries(guess, model) : 0;
  if (imposed) *imposed = n;
  return SolveHarmonicBalance(model->problem, guess, options);
}

TEST(OriginalEquations, PendulumFrequencyToRoundOffWithHalfTheUnknowns) {
  const char* file = "tests/pipeline/models/original-pendulum.yaml";
  Model model = LoadModel(file, {}, EquationsRoute::kOriginal);
  EXPECT_EQ(model.equations, "original");
  ASSERT_EQ(model.problem.system.num_variables(), 2);  // q and its chain q_d1, no auxiliaries
  // The half-wave map and two time reversals (q even, q odd).
  ASSERT_EQ(model.invariances.size(), 3u);
  int imposed = 0;
  const HarmonicBalanceSummary s = Solve(&model, 25, true, &imposed);
  ASSERT_TRUE(s.usable()) << s.FullReport();
  EXPECT_EQ(imposed, 2);  // released at rest: the half-wave map and q even
  // q condensed (q_d1 = q'), the cosines of odd harmonics 1..25 only: 13
  // coefficients + w; q'(0) = 0 holds on that subspace and is dropped.
  EXPECT_EQ(s.solver.num_unknowns, 14);
  EXPECT_EQ(s.solver.num_residuals, 14);
  const double exact = PendulumFrequency(1.5);
  EXPECT_LT(std::abs(s.solution->frequencies()[0] - exact), 2e-15) << s.FullReport();
  EXPECT_GE(s.alias_residual, 0);
  EXPECT_LT(s.alias_residual, 1e-12);

  // The same solve without the symmetries: the same answer, four times the unknowns.
  Model full = LoadModel(file, {}, EquationsRoute::kOriginal);
  const HarmonicBalanceSummary f = Solve(&full, 25, false);
  ASSERT_TRUE(f.usable());
  EXPECT_EQ(f.solver.num_unknowns, 52);
  EXPECT_LT(std::abs(f.solution->frequencies()[0] - s.solution->frequencies()[0]), 1e-15);
  EXPECT_LT((f.solution->coefficients() - s.solution->coefficients()).cwiseAbs().maxCoeff(), 1e-14);
}

// The recast truncates its auxiliaries s = sin(th), c = cos(th) at N too; the
// original equations evaluate sin(th(t)) at the samples. At N = 20 the
// original equations are within 1e-12 of the alias-free recast at N = 40
// (truncation below round-off), the recast at N = 20 is not (5.7e-10).
TEST(OriginalEquations, ForcedPendulumMoreAccurateThanTheRecastAtTheSameOrder) {
  const char* file = "tests/pipeline/models/original-forced-pendulum.yaml";
  Model reference_model = LoadModel(file);
  const HarmonicBalanceSummary reference = Solve(&reference_model, 40);
  ASSERT_TRUE(reference.usable()) << reference.FullReport();
  Model recast_model = LoadModel(file);
  const HarmonicBalanceSummary recast = Solve(&recast_model, 20);
  Model original_model = LoadModel(file, {}, EquationsRoute::kOriginal);
  const HarmonicBalanceSummary original = Solve(&original_model, 20);
  ASSERT_TRUE(recast.usable());
  ASSERT_TRUE(original.usable()) << original.FullReport();
  auto error = [&](const HarmonicSolution& s) {  // th over a period, 200 points
    double e = 0;
    const double T = 2 * M_PI / 0.8;
    for (int i = 0; i < 200; ++i)
      e = std::max(e, std::abs(s.Value(0, T * i / 200) - reference.solution->Value(0, T * i / 200)));
    return e;
  };
  std::printf("forced pendulum N = 20: original %.2e, recast %.2e\n", error(*original.solution),
              error(*recast.solution));
  EXPECT_LT(error(*original.solution), 1e-11);
  EXPECT_GT(error(*recast.solution), 100 * error(*original.solution));
  EXPECT_LT(original.alias_residual, 1e-12);
}

TEST(OriginalEquations, AutoKeepsTheRecastForPolynomialModels) {
  const Model cubic = LoadModel("tests/pipeline/models/original-cubic.yaml", {}, EquationsRoute::kAuto);
  EXPECT_EQ(cubic.equations, "recast");
  EXPECT_NE(cubic.equations_note.find("polynomial"), std::string::npos) << cubic.equations_note;
  const Model pendulum = LoadModel("tests/pipeline/models/original-pendulum.yaml", {}, EquationsRoute::kAuto);
  EXPECT_EQ(pendulum.equations, "original");
  EXPECT_EQ(ParseEquationsRoute("auto"), EquationsRoute::kAuto);
  EXPECT_THROW(ParseEquationsRoute("aft"), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb

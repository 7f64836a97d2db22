// The bundled example models: each parses, recasts with the expected degree
// phi, and solves; the solutions are checked against references (exact
// values, or a Runge-Kutta integration of the ORIGINAL equations).

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "rmhb/harmonic_balance.h"
#include "rmhb/model/recast.h"
#include "tests/model/rk4.h"

namespace rmhb::model {
namespace {

std::string ExamplePath(const std::string& name) {
  return std::string(RMHB_SOURCE_DIR) + "/examples/models/" + name + ".yaml";
}

struct Solved {
  RecastResult recast;
  HarmonicBalanceSummary summary;
};

Solved SolveExample(const std::string& name, int order, const ParameterValues& overrides = {}) {
  Solved s{Recast(LoadModelFile(ExamplePath(name)), overrides), {}};
  HarmonicBalanceOptions options;
  options.order = order;
  s.summary = SolveHarmonicBalance(s.recast.problem, s.recast.InitialGuess(order), options);
  return s;
}

// max over a few periods of |HB state - RK4 state|, integrating the original
// equations from the HB state at t = 0.
double MaxDeviationFromIntegration(const Solved& s, double t_end, int steps_per_unit = 1000) {
  OriginalSystem original = *s.recast.original;
  original.BindFrequencies(s.summary.solution->frequencies());
  std::vector<double> y = original.StateFromSolution(*s.summary.solution, 0.0);
  double worst = 0, t = 0;
  const int chunks = 20;
  for (int c = 1; c <= chunks; ++c) {
    const double t_next = t_end * c / chunks;
    y = rmhb::testing::IntegrateRk4(original, y, t, t_next,
                                    static_cast<int>(std::ceil((t_next - t) * steps_per_unit)));
    t = t_next;
    const std::vector<double> hb = original.StateFromSolution(*s.summary.solution, t);
    for (std::size_t i = 0; i < y.size(); ++i) worst = std::max(worst, std::abs(y[i] - hb[i]));
  }
  return worst;
}

TEST(ExampleModels, AllParseAndRecastWithTheExpectedDegree) {
  // Rayleigh-Plesset as written (R R'' = ...) has phi = 3: R R'', R' x, x^3,
  // R x - 1 with x = 1/R. The paper divides by R first, which gives C x^4 and
  // phi = 4 (recast_test.cc checks that form too).
  const std::vector<std::pair<std::string, int>> expected = {
      {"pendulum", 2},         {"relativistic", 4},     {"duffing", 3},      {"vanderpol", 3},
      {"forced-vanderpol", 3}, {"rayleigh-plesset", 3}, {"asym-pendulum", 3},
      {"softening-dae", 3}};
  for (const auto& [name, degree] : expected) {
    SCOPED_TRACE(name);
    const ModelDefinition m = LoadModelFile(ExamplePath(name));
    EXPECT_EQ(m.name, name);
    const RecastResult r = Recast(m);
    EXPECT_EQ(r.degree, degree) << r.Report();
    EXPECT_TRUE(r.original.has_value()) << r.original_error;
    EXPECT_TRUE(r.initial_state.has_value());
    EXPECT_TRUE(r.InitialGuess(8).coefficients().allFinite());
  }
}

TEST(ExampleModels, ParametersAsSpecified) {
  auto names = [](const std::string& model) {
    std::vector<std::string> n;
    for (const auto& p : LoadModelFile(ExamplePath(model)).parameters) n.push_back(p.name);
    return n;
  };
  EXPECT_EQ(names("duffing"), (std::vector<std::string>{"c", "k", "a", "F", "w"}));
  EXPECT_EQ(names("vanderpol"), (std::vector<std::string>{"eps"}));
  EXPECT_EQ(names("forced-vanderpol"), (std::vector<std::string>{"eps", "F", "w"}));
  EXPECT_EQ(names("pendulum"), (std::vector<std::string>{"theta0"}));
  EXPECT_EQ(names("relativistic"), (std::vector<std::string>{"beta"}));
  EXPECT_EQ(names("rayleigh-plesset"), (std::vector<std::string>{"A", "B", "C", "D", "E", "w"}));
  EXPECT_EQ(names("asym-pendulum"), (std::vector<std::string>{"kappa", "x0", "y0"}));
  const ModelDefinition asym = LoadModelFile(ExamplePath("asym-pendulum"));
  ASSERT_EQ(asym.num_bases(), 2);
  EXPECT_TRUE(asym.frequencies[0].unknown && asym.frequencies[1].unknown);
  EXPECT_EQ(asym.frequencies[0].value.text, "0.9857");
  EXPECT_EQ(asym.frequencies[1].value.text, "0.9935");
}

TEST(ExampleModels, PendulumMatchesTheExactFrequency) {
  const Solved s = SolveExample("pendulum", 25);
  ASSERT_TRUE(s.summary.converged()) << s.summary.FullReport();
  const double error = std::abs(s.summary.solution->frequencies()[0] - 0.860608346679612985103549304862);
  const double T = 2 * M_PI / s.summary.solution->frequencies()[0];
  const double deviation = MaxDeviationFromIntegration(s, 3 * T);
  std::printf("  pendulum N 25: |d omega| %.2e, RK4 deviation over 3 T %.2e\n", error, deviation);
  EXPECT_LE(error, 1e-11);
  EXPECT_LE(deviation, 1e-10);
}

TEST(ExampleModels, PendulumWithAnOverride) {
  // theta0 = 1: omega = pi / (2 K(sin^2(1/2))) = 0.9197241453998071 (quadrature).
  const Solved s = SolveExample("pendulum", 25, {{"theta0", 1.0}});
  ASSERT_TRUE(s.summary.converged());
  const double T = 2 * M_PI / s.summary.solution->frequencies()[0];
  EXPECT_NEAR(s.summary.solution->Value(0, 0.0), 1.0, 1e-13);
  EXPECT_NEAR(s.summary.solution->Value(0, T / 2), -1.0, 1e-11);
}

TEST(ExampleModels, RelativisticMatchesTheExactValues) {
  const Solved s = SolveExample("relativistic", 60);
  ASSERT_TRUE(s.summary.converged()) << s.summary.FullReport();
  const double w = s.summary.solution->frequencies()[0];
  const double amplitude = s.summary.solution->Value(0, M_PI / (2 * w));
  std::printf("  relativistic N 60: |d omega| %.2e, |d A| %.2e\n",
              std::abs(w - 0.769790190987922482444839653363),
              std::abs(amplitude - 1.34038501297574794295514979307));
  EXPECT_NEAR(w, 0.769790190987922482444839653363, 1e-11);
  EXPECT_NEAR(amplitude, 1.34038501297574794295514979307, 1e-11);
}

TEST(ExampleModels, VanDerPolLimitCycle) {
  const Solved s = SolveExample("vanderpol", 60);
  ASSERT_TRUE(s.summary.converged()) << s.summary.FullReport();
  const double T = 2 * M_PI / s.summary.solution->frequencies()[0];
  const double x_max = s.summary.solution->Value(0, 0.0);  // x'(0) = 0 at the maximum
  std::printf("  vanderpol eps 1 N 60: |d T| %.2e, |d max x| %.2e\n",
              std::abs(T - 6.6632868593231301897), std::abs(x_max - 2.0086198608748431365));
  EXPECT_NEAR(T, 6.6632868593231301897, 1e-10);
  EXPECT_NEAR(x_max, 2.0086198608748431365, 1e-10);
}

// Forced models: the harmonic balance solution against a Runge-Kutta
// integration of the original equations started from it. (forced-vanderpol
// is quasi-periodic: model_vs_example_test.cc compares it with the C++
// example, which quasi_periodic_test.cc checks against CVODE.)
TEST(ExampleModels, ForcedModelsAgreeWithIntegration) {
  for (const auto& [name, order] : std::vector<std::pair<std::string, int>>{
           {"duffing", 30}, {"rayleigh-plesset", 30}}) {
    SCOPED_TRACE(name);
    const Solved s = SolveExample(name, order);
    ASSERT_TRUE(s.summary.converged()) << s.summary.FullReport();
    const double T = 2 * M_PI / s.summary.solution->frequencies()[0];
    const double deviation = MaxDeviationFromIntegration(s, 3 * T);
    std::printf("  %s N %d: RK4 deviation over 3 T %.2e\n", name.c_str(), order, deviation);
    EXPECT_LE(deviation, 1e-9);
  }
}

}  // namespace
}  // namespace rmhb::model

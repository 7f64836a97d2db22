// The original equations as an explicit ODE for the integrators.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "rmhb/model/original_system.h"
#include "rmhb/model/recast.h"

namespace rmhb::model {
namespace {

OriginalSystem Build(const std::string& text, const ParameterValues& overrides = {}) {
  const ModelDefinition m = ParseModel(text, "m.yaml");
  std::vector<double> w;
  for (const auto& f : m.frequencies) w.push_back(std::stod(f.value.text));
  return BuildOriginalSystem(m, overrides, w);
}

std::vector<double> Rhs(const OriginalSystem& s, double t, std::vector<double> y) {
  std::vector<double> ydot(y.size());
  s.rhs(t, y.data(), ydot.data());
  return ydot;
}

TEST(OriginalSystem, Pendulum) {
  const OriginalSystem s = Build(
      "variables: [theta]\nequations: [\"theta'' + sin(theta) = 0\"]\nfrequencies: [{guess: 1}]\n");
  EXPECT_EQ(s.dimension, 2);
  EXPECT_EQ(s.state_names, (std::vector<std::string>{"theta", "theta'"}));
  const auto f = Rhs(s, 0.0, {0.7, -0.3});
  EXPECT_DOUBLE_EQ(f[0], -0.3);
  EXPECT_DOUBLE_EQ(f[1], -std::sin(0.7));
}

TEST(OriginalSystem, StateDependentMassRayleighPlesset) {
  const OriginalSystem s = Build(
      "variables: [R]\nparameters: {A: 0.1, B: 1, C: 2, D: -1, E: 0.2, w: 2}\n"
      "equations: [\"R*R'' = -3/2*R'^2 - A*R'/R - B/R + C/R^3 + D - E*cos(w*t)\"]\n"
      "frequencies: [2]\n");
  const double R = 1.3, v = 0.4, t = 0.9;
  const double expected =
      (-1.5 * v * v - 0.1 * v / R - 1 / R + 2 / (R * R * R) - 1 - 0.2 * std::cos(2 * t)) / R;
  const auto f = Rhs(s, t, {R, v});
  EXPECT_DOUBLE_EQ(f[0], v);
  EXPECT_NEAR(f[1], expected, 1e-15);
}

TEST(OriginalSystem, CoupledMassMatrixAsymmetricPendulum) {
  const OriginalSystem s = Build(
      "variables: [x, y]\nparameters: {k: 0.01}\n"
      "equations:\n"
      "  - \"x'' + (1 - k)*x = -(1 - k)*(x*x'^2 + x*y'^2 + x*y*y'' + x^2*x'')\"\n"
      "  - \"y'' + y = -(y*y'^2 + y*x'^2 + x*y*x'' + y^2*y'')\"\n"
      "frequencies: [{guess: 0.98}, {guess: 0.99}]\n");
  EXPECT_EQ(s.state_names, (std::vector<std::string>{"x", "x'", "y", "y'"}));
  const double x = 0.3, vx = -0.2, y = 0.5, vy = 0.1, k = 0.01;
  // [1 + (1-k) x^2, (1-k) x y; x y, 1 + y^2] [x''; y''] = b
  const double a11 = 1 + (1 - k) * x * x, a12 = (1 - k) * x * y, a21 = x * y, a22 = 1 + y * y;
  const double b1 = -(1 - k) * x - (1 - k) * (x * vx * vx + x * vy * vy);
  const double b2 = -y - (y * vy * vy + y * vx * vx);
  const double det = a11 * a22 - a12 * a21;
  const auto f = Rhs(s, 0.0, {x, vx, y, vy});
  EXPECT_DOUBLE_EQ(f[0], vx);
  EXPECT_DOUBLE_EQ(f[2], vy);
  EXPECT_NEAR(f[1], (b1 * a22 - a12 * b2) / det, 1e-15);
  EXPECT_NEAR(f[3], (a11 * b2 - a21 * b1) / det, 1e-15);

  // Cost of one evaluation (the integrators call it millions of times).
  std::vector<double> yv{x, vx, y, vy}, ydot(4);
  const int n = 200000;
  const auto start = std::chrono::steady_clock::now();
  double sink = 0;
  for (int i = 0; i < n; ++i) {
    yv[0] = x + 1e-9 * i;
    s.rhs(0.0, yv.data(), ydot.data());
    sink += ydot[1];
  }
  const double ns =
      std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count() / n;
  std::printf("  asymmetric pendulum rhs: %.0f ns per evaluation (%g)\n", ns, sink);
}

TEST(OriginalSystem, ThirdOrderWithForcingAndFrequencyRebinding) {
  OriginalSystem s = Build(
      "variables: [x]\nparameters: {F: 0.5}\n"
      "equations: [\"x''' + 2*x'' + x' + x^3 = F*cos(w*t)\"]\nfrequencies: [{guess: 1.5}]\n");
  EXPECT_EQ(s.state_names, (std::vector<std::string>{"x", "x'", "x''"}));
  auto f = Rhs(s, 0.4, {0.2, 0.3, -0.1});
  EXPECT_DOUBLE_EQ(f[0], 0.3);
  EXPECT_DOUBLE_EQ(f[1], -0.1);
  EXPECT_NEAR(f[2], 0.5 * std::cos(1.5 * 0.4) - 2 * -0.1 - 0.3 - 0.008, 1e-15);
  s.BindFrequencies({2.5});
  f = Rhs(s, 0.4, {0.2, 0.3, -0.1});
  EXPECT_NEAR(f[2], 0.5 * std::cos(2.5 * 0.4) - 2 * -0.1 - 0.3 - 0.008, 1e-15);
}

TEST(OriginalSystem, SingularMassGivesNaN) {
  const OriginalSystem s = Build("variables: [x]\nequations: [\"x*x'' + 1 = 0\"]\nfrequencies: [1]\n");
  const auto f = Rhs(s, 0.0, {0.0, 1.0});
  EXPECT_TRUE(std::isnan(f[1]));
}

TEST(OriginalSystem, RefusesNonlinearHighestDerivativesAndPurelyAlgebraicModels) {
  try {
    Build("variables: [x]\nequations: [\"x'' + sin(x'') + x = 0\"]\nfrequencies: [1]\n");
    ADD_FAILURE();
  } catch (const ModelError& e) {
    EXPECT_STREQ(e.what(),
                 "m.yaml:2:14: the highest derivatives appear nonlinearly in equation 1: the "
                 "integrators need them linearly (M(y) y_high = b(t, y))");
  }
  // An algebraic variable makes a DAE (dae_model_test.cc); no derivative at
  // all leaves nothing to integrate.
  EXPECT_TRUE(
      Build("variables: [x, y]\nequations: [\"x' + y = 0\", \"y - x^2 = cos(w*t)\"]\nfrequencies: [1]\n")
          .is_dae());
  try {
    Build("variables: [x]\nequations: [\"x^2 - 2 = cos(w*t)\"]\nfrequencies: [1]\n");
    ADD_FAILURE();
  } catch (const ModelError& e) {
    EXPECT_STREQ(e.what(), "m.yaml: no variable has a derivative: the equations are purely algebraic");
  }
  // The recast still works; it reports why there is no original system.
  const RecastResult r = Recast(ParseModel(
      "variables: [x]\nequations: [\"x'' + sin(x'') + x = cos(w*t)\"]\nfrequencies: [1]\n", "m.yaml"));
  EXPECT_FALSE(r.original.has_value());
  EXPECT_NE(r.original_error.find("nonlinearly"), std::string::npos);
}

TEST(OriginalSystem, MappingFromTheRecastSolution) {
  const RecastResult r = Recast(ParseModel(
      "variables: [x, y]\n"
      "equations: [\"x'' + x + y = 0\", \"y' + exp(y) - 1 + x = 0\"]\nfrequencies: [{guess: 1}]\n"
      "guess: {x: \"cos(w*t)\", y: \"sin(w*t)/2\"}\n",
      "m.yaml"));
  ASSERT_TRUE(r.original.has_value());
  const OriginalSystem& s = *r.original;
  EXPECT_EQ(s.state_names, (std::vector<std::string>{"x", "x'", "y"}));
  ASSERT_EQ(s.sources.size(), 3u);
  const auto names = r.problem.system.names();
  EXPECT_EQ(names[s.sources[0].variable], "x");
  EXPECT_EQ(names[s.sources[1].variable], "x_d1");
  EXPECT_EQ(names[s.sources[2].variable], "y");
  const HarmonicSolution g = r.InitialGuess(8);
  const auto y = s.StateFromSolution(g, 0.3);
  EXPECT_NEAR(y[0], std::cos(0.3), 1e-14);
  EXPECT_NEAR(y[1], -std::sin(0.3), 1e-14);
  EXPECT_NEAR(y[2], std::sin(0.3) / 2, 1e-14);
}

}  // namespace
}  // namespace rmhb::model

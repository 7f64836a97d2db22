// Taylor-expanded models (RHB-Taylor): the expansion checked against the
// Taylor series written out by hand, through the compiled original system.

#include "rmhb/model/taylor_expansion.h"

#include <gtest/gtest.h>

#include <cmath>

#include "rmhb/model/original_system.h"
#include "rmhb/model/recast.h"

namespace rmhb::model {
namespace {

std::string Model(const std::string& name) { return "examples/models/" + name + ".yaml"; }

double Acceleration(const ModelDefinition& m, double x, double v) {
  const OriginalSystem s = BuildOriginalSystem(m, {}, {1.0});
  const double y[2] = {x, v};
  double dy[2];
  s.rhs(0.0, y, dy);
  return dy[1];
}

TEST(TaylorExpansion, PendulumSineBecomesItsSeries) {
  const ModelDefinition m = LoadModelFile(Model("pendulum"));
  ASSERT_TRUE(HasNonPolynomialTerms(m));
  const ModelDefinition t5 = TaylorExpanded(m, 5);
  EXPECT_FALSE(HasNonPolynomialTerms(t5));
  EXPECT_EQ(t5.name, "pendulum-taylor5");
  const double th = 0.7;
  EXPECT_NEAR(Acceleration(t5, th, 0), -(th - std::pow(th, 3) / 6 + std::pow(th, 5) / 120), 1e-15);
  const RecastResult r = Recast(t5);
  EXPECT_EQ(r.degree, 5);  // phi = Taylor order: no auxiliaries
  for (const auto& v : r.problem.system.variables()) EXPECT_EQ(v.role, VariableRole::kState) << v.name;
  // Order 15 at theta0 = 1.5: the truncation is 1.5^17/17! ~ 3e-12 relative to sin.
  const ModelDefinition t15 = TaylorExpanded(m, 15);
  EXPECT_NEAR(Acceleration(t15, 1.5, 0), -std::sin(1.5), 5e-12);
  EXPECT_GT(std::abs(Acceleration(t15, 1.5, 0) + std::sin(1.5)), 1e-13);
}

TEST(TaylorExpansion, MultivariateTotalDegree) {
  // x'' + (1 - x'^2)^(3/2) x: to total degree 5 the coefficient of x is
  // 1 - 3/2 v^2 + 3/8 v^4.
  const ModelDefinition t = TaylorExpanded(LoadModelFile(Model("relativistic")), 5);
  const double x = 0.3, v = 0.4;
  EXPECT_NEAR(Acceleration(t, x, v), -(1 - 1.5 * v * v + 0.375 * std::pow(v, 4)) * x, 1e-15);
  EXPECT_EQ(Recast(t).degree, 5);
}

TEST(TaylorExpansion, PolynomialModelsAndPoles) {
  const ModelDefinition duffing = LoadModelFile(Model("duffing"));
  EXPECT_FALSE(HasNonPolynomialTerms(duffing));
  // Forcing cos(w t) carries no state and stays as it is.
  EXPECT_EQ(Recast(TaylorExpanded(duffing, 3)).degree, Recast(duffing).degree);
  // R R'' = ... - B/R: no expansion about R = 0; the error names the equation.
  try {
    TaylorExpanded(LoadModelFile(Model("rayleigh-plesset")), 5);
    FAIL() << "expected a ModelError";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("rayleigh-plesset.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("Taylor"), std::string::npos) << e.what();
  }
  EXPECT_THROW(TaylorExpanded(duffing, 0), ModelError);
}

}  // namespace
}  // namespace rmhb::model

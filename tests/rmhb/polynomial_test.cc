#include "rmhb/polynomial_system.h"

#include <gtest/gtest.h>

#include "rmhb/sampling.h"

namespace rmhb {
namespace {

TEST(Polynomial, TimeFunctionProductsExpand) {
  // cos(w t) * cos(w t) = 1/2 + cos(2 w t)/2
  const Polynomial p = Polynomial::Cos({1}) * Polynomial::Cos({1});
  ASSERT_EQ(p.terms().size(), 2u);
  for (const auto& [m, c] : p.terms()) EXPECT_DOUBLE_EQ(c, 0.5);
  // sin(w t) * cos(w t) = sin(2 w t)/2 ; sin(-w t) = -sin(w t)
  const Polynomial q = Polynomial::Sin({1}) * Polynomial::Cos({1}) + Polynomial::Sin({-2}, 0.5);
  EXPECT_TRUE(q.IsZero());
}

TEST(Polynomial, DegreeCountsDerivativesLikeStates) {
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("u");
  s.AddEquation(s.D("x") - s.Var("u"));
  s.AddEquation(s.D("u") + s.Var("x") * s.Var("x") * s.D("x"));
  EXPECT_EQ(s.Degree(), 3);
}

TEST(PolynomialSystem, AliasBoundIsTheoremOneWithForcing) {
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("v");
  s.AddEquation(s.D("x") - s.Var("v"));
  s.AddEquation(s.D("v") + Pow(s.Var("x"), 3) - Polynomial::Cos({1}));
  EXPECT_EQ(s.AliasFreeSamples(10), 4 * 10 + 1);  // (phi+1) N + 1
  // A forcing harmonic multiplying a cubic shifts the spectrum by 2.
  PolynomialSystem t;
  t.AddVariable("x");
  t.AddEquation(t.D("x") + Pow(t.Var("x"), 3) * Polynomial::Cos({2}));
  EXPECT_EQ(t.AliasFreeSamples(10), 4 * 10 + 2 + 1);
  EXPECT_EQ(FftFriendlySize(41), 42);
  EXPECT_EQ(FftFriendlySize(121), 125);
}

TEST(PolynomialSystem, ValidateNamesTheProblem) {
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("y");
  s.AddEquation(s.D("x") - s.Var("x"));
  try {
    s.Validate();
    FAIL() << "expected a throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("1 equations for 2 variables"), std::string::npos);
  }
  EXPECT_THROW(s.AddVariable("x"), std::invalid_argument);
  EXPECT_THROW(s.Var("nope"), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb

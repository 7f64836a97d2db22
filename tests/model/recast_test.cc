// Structure of the recast: which auxiliaries, which equations, which degree,
// which conditions; the guess of the auxiliaries; forcing terms as time
// functions. The numerical equivalence is in recast_solve_test.cc.

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rmhb/harmonic_balance.h"
#include "rmhb/model/recast.h"

namespace rmhb::model {
namespace {

RecastResult RecastText(const std::string& text, const ParameterValues& overrides = {}) {
  return Recast(ParseModel(text, "test.yaml"), overrides);
}

// A one-variable free model around `equation` (in x).
std::string Free(const std::string& equation, const std::string& extra = "") {
  return "variables: [x]\nparameters: {A: 0.5}\nequations: [\"" + equation +
         "\"]\nfrequencies: [{guess: 1}]\nconditions: [\"x(0) = A\", \"x'(0) = 0\"]\n"
         "guess: {x: \"A*cos(w*t)\"}\n" + extra;
}

std::vector<std::string> Names(const RecastResult& r) { return r.problem.system.names(); }

std::vector<std::string> Equations(const RecastResult& r) {
  std::vector<std::string> out;
  const auto names = r.problem.system.names();
  for (const auto& e : r.problem.system.equations()) out.push_back(e.lhs.ToString(names));
  return out;
}

int CountAuxiliaries(const RecastResult& r) {
  int n = 0;
  for (const auto& v : r.problem.system.variables()) n += v.role == VariableRole::kAuxiliary;
  return n;
}

int CountUnbalanced(const RecastResult& r) {
  int n = 0;
  for (const auto& e : r.problem.system.equations()) n += !e.balance_constant;
  return n;
}

bool HasEquation(const RecastResult& r, const std::string& text) {
  for (const auto& e : Equations(r))
    if (e == text) return true;
  return false;
}

std::string Dump(const RecastResult& r) { return r.Report(); }

// The auxiliary defined as `definition` (GiNaC's printed form), or "".
std::string NameOf(const RecastResult& r, const std::string& definition) {
  for (const auto& v : r.problem.system.variables())
    if (v.role == VariableRole::kAuxiliary && v.definition == definition) return v.name;
  return "";
}

// Every auxiliary's guess equals its definition on the guessed states: the
// pinning conditions vanish on the guess at t = 0.
void ExpectPinsHoldAtTheGuess(const RecastResult& r) {
  const Eigen::VectorXd z = r.guess(std::vector<double>(r.problem.frequencies.size(), 0.0));
  const int n = static_cast<int>(z.size());
  Eigen::VectorXd dz = Eigen::VectorXd::Zero(n), gz(n), gdz(n);
  for (std::size_t i = r.num_user_conditions; i < r.problem.conditions.size(); ++i) {
    gz.setZero();
    gdz.setZero();
    EXPECT_NEAR(r.problem.conditions[i].function(z, dz, &gz, &gdz), 0.0, 1e-15)
        << r.problem.conditions[i].description;
  }
  // And the guess projects to a finite solution.
  EXPECT_TRUE(r.InitialGuess(8).coefficients().allFinite());
}

// ---- derivative chains ----------------------------------------------------------------
TEST(Recast, SecondOrderEquationGetsAVelocityState) {
  const RecastResult r = RecastText(Free("x'' + x + x^3 = 0"));
  EXPECT_EQ(Names(r), (std::vector<std::string>{"x", "x_d1"}));
  EXPECT_EQ(r.problem.system.variables()[1].role, VariableRole::kState);
  EXPECT_EQ(r.problem.system.variables()[1].definition, "x'");
  EXPECT_TRUE(HasEquation(r, "x' - x_d1")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "x + x^3 + x_d1'")) << Dump(r);
  EXPECT_EQ(r.degree, 3);
  EXPECT_EQ(CountAuxiliaries(r), 0);
}

TEST(Recast, ThirdOrderChain) {
  const RecastResult r = RecastText(Free("x''' + x'' + x' + x^2 = 0"));
  EXPECT_EQ(Names(r), (std::vector<std::string>{"x", "x_d1", "x_d2"}));
  EXPECT_TRUE(HasEquation(r, "x' - x_d1"));
  EXPECT_TRUE(HasEquation(r, "x_d1' - x_d2"));
  EXPECT_TRUE(HasEquation(r, "x^2 + x_d1 + x_d2 + x_d2'")) << Dump(r);
  EXPECT_EQ(r.degree, 2);
}

TEST(Recast, FirstOrderEquationNeedsNoChain) {
  const RecastResult r = RecastText(
      "variables: [x]\nequations: [\"x' = -x - x^3 + cos(w*t)\"]\nfrequencies: [1]\n");
  EXPECT_EQ(Names(r), (std::vector<std::string>{"x"}));
  EXPECT_EQ(r.degree, 3);
}

TEST(Recast, DerivativeCouplingVanDerPol) {
  // rmhb/METHOD.md s.4 rule 1: x' = u, u' = eps u - x - eps x^2 u + F cos wt, phi = 3.
  const RecastResult r = RecastText(
      "variables: [x]\nparameters: {eps: 0.5, F: 2}\n"
      "equations: [\"x'' - eps*(1 - x^2)*x' + x = F*cos(w*t)\"]\nfrequencies: [1.3]\n");
  EXPECT_EQ(r.degree, 3);
  EXPECT_TRUE(HasEquation(r, "-2*cos((w) t) + x + 0.5*x^2*x_d1 - 0.5*x_d1 + x_d1'")) << Dump(r);
}

TEST(Recast, SecondDerivativesInsideNonlinearTermsStayImplicit) {
  // The asymmetric pendulum (rmhb/METHOD.md eq. 25): x y y'' is the cubic x y (y_d1)'.
  const RecastResult r = RecastText(
      "variables: [x, y]\nparameters: {k: 0.01}\n"
      "equations:\n"
      "  - \"x'' + (1 - k)*x = -(1 - k)*(x*x'^2 + x*y'^2 + x*y*y'' + x^2*x'')\"\n"
      "  - \"y'' + y = -(y*y'^2 + y*x'^2 + x*y*x'' + y^2*y'')\"\n"
      "frequencies: [{guess: 0.98}, {guess: 0.99}]\n");
  EXPECT_EQ(Names(r), (std::vector<std::string>{"x", "x_d1", "y", "y_d1"}));
  EXPECT_EQ(CountAuxiliaries(r), 0);
  EXPECT_EQ(r.degree, 3);
  EXPECT_TRUE(HasEquation(r, "x*x_d1'*y + x_d1^2*y + y + y*y_d1^2 + y^2*y_d1' + y_d1'")) << Dump(r);
}

TEST(Recast, TranscendentalOfTheTopDerivativeExtendsTheChain) {
  // sin(x') with x' the top derivative: its derivative needs x'', so x'
  // becomes a state x_d1 and the equation turns algebraic in x_d1.
  const RecastResult r = RecastText(
      "variables: [x]\nequations: [\"x' + x + sin(x')/10 = cos(w*t)\"]\nfrequencies: [1]\n");
  EXPECT_EQ(Names(r), (std::vector<std::string>{"x", "x_d1", "sin_x_d1", "cos_x_d1"}));
  EXPECT_TRUE(HasEquation(r, "x' - x_d1"));
  EXPECT_TRUE(HasEquation(r, "-x_d1'*cos_x_d1 + sin_x_d1'")) << Dump(r);
  ExpectPinsHoldAtTheGuess(r);
}

// ---- appendix rows -----------------------------------------------------------------------
TEST(Recast, Exp) {
  const RecastResult r = RecastText(Free("x'' + exp(x) - 1 = 0"));
  EXPECT_EQ(Names(r), (std::vector<std::string>{"x", "x_d1", "exp_x"}));
  EXPECT_EQ(r.definitions, (std::vector<std::string>{"exp_x = exp(x)"}));
  EXPECT_TRUE(HasEquation(r, "-x_d1*exp_x + exp_x'")) << Dump(r);
  EXPECT_EQ(CountUnbalanced(r), 1);
  ASSERT_EQ(r.problem.conditions.size(), 3u);  // x(0), x'(0), pin
  EXPECT_EQ(r.num_user_conditions, 2);
  EXPECT_EQ(r.degree, 2);
  ExpectPinsHoldAtTheGuess(r);
}

TEST(Recast, LogNaturalBaseAndLog10) {
  const RecastResult r = RecastText(Free("x'' + log(1 + x) + log10(2 + x) - log10(2) = 0"));
  // log(1+x): r = 1/(1+x), u' = x' r; log10(2+x) = log(2+x)/log(10).
  EXPECT_EQ(CountAuxiliaries(r), 4) << Dump(r);
  const std::string inv = NameOf(r, "1/(1 + x)"), log = NameOf(r, "log(1 + x)");
  EXPECT_TRUE(HasEquation(r, "-1 + x*" + inv + " + " + inv)) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "-x_d1*" + inv + " + " + log + "'")) << Dump(r);
  EXPECT_EQ(CountUnbalanced(r), 2);
  EXPECT_EQ(r.degree, 2);
  ExpectPinsHoldAtTheGuess(r);
}

TEST(Recast, SinAndCosArePairedAndShared) {
  const RecastResult r = RecastText(Free("x'' + sin(x) + cos(x)*sin(x)^3 = 0"));
  EXPECT_EQ(Names(r), (std::vector<std::string>{"x", "x_d1", "sin_x", "cos_x"}));
  EXPECT_TRUE(HasEquation(r, "-x_d1*cos_x + sin_x'")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "x_d1*sin_x + cos_x'")) << Dump(r);
  EXPECT_EQ(CountUnbalanced(r), 2);
  EXPECT_EQ(r.degree, 4);  // cos(x) sin(x)^3
  ExpectPinsHoldAtTheGuess(r);
}

TEST(Recast, PendulumAsInThePaper) {
  // rmhb/METHOD.md eq. 20: theta' = v, v' = -s, s' = c v, c' = -s v, phi = 2.
  const RecastResult r = RecastText(
      "variables: [theta]\nparameters: {theta0: 1.5}\nequations: [\"theta'' + sin(theta) = 0\"]\n"
      "frequencies: [{guess: 0.86}]\nconditions: [\"theta(0) = theta0\", \"theta'(0) = 0\"]\n"
      "guess: {theta: \"theta0*cos(w*t)\"}\n");
  EXPECT_EQ(Equations(r), (std::vector<std::string>{"theta' - theta_d1", "theta_d1' + sin_theta",
                                                     "-theta_d1*cos_theta + sin_theta'",
                                                     "theta_d1*sin_theta + cos_theta'"}));
  EXPECT_EQ(r.degree, 2);
  ASSERT_EQ(r.problem.conditions.size(), 4u);
  EXPECT_EQ(r.problem.conditions[2].description, "pin sin_theta(0) = sin(theta)");
  ExpectPinsHoldAtTheGuess(r);
}

TEST(Recast, Tan) {
  const RecastResult r = RecastText(Free("x'' + tan(x) = 0"));
  EXPECT_TRUE(HasEquation(r, "-x_d1 - x_d1*tan_x^2 + tan_x'")) << Dump(r);
  EXPECT_EQ(r.degree, 3);
}

TEST(Recast, AsinAndAcosShareTheirRadical) {
  const RecastResult r = RecastText(Free("x'' + asin(x) + acos(x) - pi/2 + x = 0"));
  // v = sqrt(1 - x^2), w = 1/v, u1 = asin x, u2 = acos x: four auxiliaries.
  EXPECT_EQ(CountAuxiliaries(r), 4) << Dump(r);
  EXPECT_EQ(NameOf(r, "sqrt(1 - x^2)"), "sqrt_1");
  EXPECT_EQ(NameOf(r, "1/sqrt_1"), "inv_sqrt_1");
  EXPECT_EQ(NameOf(r, "asin(x)"), "asin_x");
  EXPECT_EQ(NameOf(r, "acos(x)"), "acos_x");
  EXPECT_TRUE(HasEquation(r, "-1 + x^2 + sqrt_1^2")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "-1 + sqrt_1*inv_sqrt_1")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "-x_d1*inv_sqrt_1 + asin_x'")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "x_d1*inv_sqrt_1 + acos_x'")) << Dump(r);
  EXPECT_EQ(r.degree, 2);
  ExpectPinsHoldAtTheGuess(r);
}

TEST(Recast, AtanNamesItsDenominator) {
  // Appendix: v = 1 + x^2, w = 1/v, w v - 1 = 0, v - x^2 - 1 = 0: phi = 2.
  const RecastResult r = RecastText(Free("x'' + atan(x) = 0"));
  EXPECT_TRUE(HasEquation(r, "-1 - x^2 + den_1")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "-1 + den_1*inv_den_1")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "-x_d1*inv_den_1 + atan_x'")) << Dump(r);
  EXPECT_EQ(r.degree, 2);
}

TEST(Recast, Hyperbolic) {
  const RecastResult r = RecastText(Free("x'' + sinh(x) + cosh(x) - 1 + tanh(x) = 0"));
  EXPECT_EQ(Names(r), (std::vector<std::string>{"x", "x_d1", "sinh_x", "cosh_x", "tanh_x"}));
  EXPECT_TRUE(HasEquation(r, "-x_d1*cosh_x + sinh_x'")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "-x_d1*sinh_x + cosh_x'")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "-x_d1 + x_d1*tanh_x^2 + tanh_x'")) << Dump(r);
  EXPECT_EQ(CountUnbalanced(r), 3);
  EXPECT_EQ(r.degree, 3);
  ExpectPinsHoldAtTheGuess(r);
}

// ---- algebraic rules ---------------------------------------------------------------------
TEST(Recast, RationalPowersShareOneReciprocal) {
  // Rayleigh-Plesset as written: 1/R, 1/R^3 and R'/R all use x = 1/R.
  const RecastResult r = RecastText(
      "variables: [R]\nparameters: {A: 0.1, B: 1, C: 2, D: -1, E: 0.2, w: 2}\n"
      "equations: [\"R*R'' = -3/2*R'^2 - A*R'/R - B/R + C/R^3 + D - E*cos(w*t)\"]\n"
      "frequencies: [w]\n");
  EXPECT_EQ(Names(r), (std::vector<std::string>{"R", "R_d1", "inv_R"}));
  EXPECT_TRUE(HasEquation(r, "-1 + R*inv_R")) << Dump(r);
  EXPECT_EQ(r.degree, 3);  // R R'', R' x, x^3, R x
}

TEST(Recast, RayleighPlessetInThePapersFormHasDegreeFour) {
  // Divided by R first, as the paper does (eq. 16 -> v' = ... + C x^4 ...).
  const RecastResult r = RecastText(
      "variables: [R]\nparameters: {A: 0.1, B: 1, C: 2, D: -1, E: 0.2, w: 2}\n"
      "equations: [\"R'' = -3/2*R'^2/R - A*R'/R^2 - B/R^2 + C/R^4 + D/R - E*cos(w*t)/R\"]\n"
      "frequencies: [w]\n");
  EXPECT_EQ(Names(r), (std::vector<std::string>{"R", "R_d1", "inv_R"}));
  EXPECT_EQ(r.degree, 4);
}

TEST(Recast, RadicalOfTheVelocity) {
  // Relativistic oscillator (rmhb/METHOD.md eq. 18): u^2 + v^2 - 1 = 0, v' + u^3 x = 0, phi 4.
  const RecastResult r = RecastText(Free("x'' + (1 - x'^2)^(3/2)*x = 0"));
  EXPECT_EQ(Names(r), (std::vector<std::string>{"x", "x_d1", "sqrt_1"}));
  EXPECT_TRUE(HasEquation(r, "-1 + x_d1^2 + sqrt_1^2")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "x*sqrt_1^3 + x_d1'")) << Dump(r);
  EXPECT_EQ(CountUnbalanced(r), 0);
  EXPECT_EQ(r.problem.conditions.size(), 2u);  // algebraic: no pins
  EXPECT_EQ(r.degree, 4);
}

TEST(Recast, NegativeAndCubicRoots) {
  const RecastResult r = RecastText(Free("x'' + x*(1 + x^2)^(-1/2) + (1 + x)^(1/3) - 1 = 0"));
  EXPECT_TRUE(HasEquation(r, "-1 - x^2 + sqrt_1^2")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "-1 + sqrt_1*inv_sqrt_1")) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "-1 - x + cbrt_1^3")) << Dump(r);
  EXPECT_EQ(r.degree, 3);
  ExpectPinsHoldAtTheGuess(r);
}

TEST(Recast, OtherRealPowersUseTheDerivativeRule) {
  const RecastResult r = RecastText(Free("x'' + x*(2 + x)^0.3 = 0"));
  // u = (2+x)^(3/10): u' - 3/10 x' u r, r = 1/(2+x).
  EXPECT_TRUE(HasEquation(r, "-0.3*x_d1*inv_1*pow_1 + pow_1'")) << Dump(r);
  EXPECT_EQ(r.degree, 3);
  ExpectPinsHoldAtTheGuess(r);
}

TEST(Recast, VariableExponentGoesThroughExpAndLog) {
  const RecastResult r = RecastText(Free("x'' + (2 + x)^(1 + x) - 2 = 0"));
  EXPECT_EQ(CountAuxiliaries(r), 3) << Dump(r);  // 1/(2+x), log(2+x), exp(...)
  ExpectPinsHoldAtTheGuess(r);
}

// ---- compositions, sharing -----------------------------------------------------------------
TEST(Recast, NestedSinOfExp) {
  const RecastResult r = RecastText(Free("x'' + sin(exp(x)) - sin(1) = 0"));
  EXPECT_EQ(Names(r), (std::vector<std::string>{"x", "x_d1", "exp_x", "sin_exp_x", "cos_exp_x"}))
      << Dump(r);
  EXPECT_TRUE(HasEquation(r, "-exp_x'*cos_exp_x + sin_exp_x'")) << Dump(r);
  EXPECT_EQ(r.degree, 2);
  ExpectPinsHoldAtTheGuess(r);
}

TEST(Recast, NestedReciprocalOfTrigonometric) {
  const RecastResult r = RecastText(Free("x'' + 1/(1 + sin(x)^2) - 1 = 0"));
  EXPECT_EQ(Names(r), (std::vector<std::string>{"x", "x_d1", "sin_x", "cos_x", "den_1", "inv_den_1"}))
      << Dump(r);
  EXPECT_TRUE(HasEquation(r, "-1 - sin_x^2 + den_1")) << Dump(r);
  EXPECT_EQ(r.degree, 2);
  ExpectPinsHoldAtTheGuess(r);
}

TEST(Recast, CommonSubexpressionsAreRecastOnce) {
  const RecastResult r = RecastText(
      "variables: [x, y]\n"
      "equations: [\"x'' + exp(x - y) + 1/(1 + x^2) = 0\", \"y'' + x*exp(x - y) - 1/(1 + x^2) = 0\"]\n"
      "frequencies: [{guess: 1}]\n");
  EXPECT_EQ(CountAuxiliaries(r), 3) << Dump(r);  // exp(x - y), 1 + x^2, its inverse
}

// ---- forcing -------------------------------------------------------------------------------
TEST(Recast, ForcingBecomesTimeFunctions) {
  const RecastResult r = RecastText(
      "variables: [x]\nparameters: {F: 0.3}\n"
      "equations: [\"x'' + x + x^3 = F*cos(w*t) + F*x*sin(2*w*t) + cos(3*w*t + pi/2)\"]\n"
      "frequencies: [1.5]\n");
  EXPECT_EQ(CountAuxiliaries(r), 0);
  EXPECT_EQ(r.degree, 3);
  EXPECT_EQ(r.problem.system.ForcingReach(0), 3);
  EXPECT_TRUE(HasEquation(r, "-0.3*cos((w) t) + sin((3 w) t) + x - 0.3*x*sin((2 w) t) + x^3 + x_d1'"))
      << Dump(r);
}

TEST(Recast, TwoBaseForcing) {
  const RecastResult r = RecastText(
      "variables: [x]\nequations: [\"x'' + x = cos((w1 + 2*w2)*t) + sin(w1*t - w2*t)\"]\n"
      "frequencies: [1, {guess: 1.41}]\n");
  EXPECT_TRUE(HasEquation(r, "-cos((w1 + 2 w2) t) - sin((w1 - w2) t) + x + x_d1'")) << Dump(r);
  EXPECT_EQ(r.problem.system.ForcingReach(1), 2);
}

TEST(Recast, ForcingFrequencyGivenAsAParameter) {
  // The base is the parameter Omega; cos(4*t) is matched numerically (Omega = 2).
  const std::string text =
      "variables: [x]\nparameters: {Omega: 2}\n"
      "equations: [\"x'' + x = cos(Omega*t) + cos(4*t)\"]\nfrequencies: [Omega]\n";
  const RecastResult r = RecastText(text);
  EXPECT_TRUE(HasEquation(r, "-cos((w) t) - cos((2 w) t) + x + x_d1'")) << Dump(r);
  EXPECT_DOUBLE_EQ(RecastText(text, {{"Omega", 4}}).problem.frequencies[0], 4.0);
  try {
    RecastText(text, {{"Omega", 3}});  // cos(4 t) is no harmonic of 3
    ADD_FAILURE() << "expected a ModelError";
  } catch (const ModelError& e) {
    EXPECT_STREQ(e.what(),
                 "test.yaml:3:14: cos(4*t) is not a harmonic of the base frequencies: time may "
                 "only appear as cos(k*w*t + phase), sin(k*w*t + phase) with integer k in "
                 "equation 1");
  }
}

TEST(Recast, TranscendentalForcingOfAKnownFrequency) {
  // exp(cos(w t)) is not a finite Fourier series: it is recast like any exp.
  const RecastResult r = RecastText(
      "variables: [x]\nequations: [\"x'' + x/10 + x' = exp(cos(w*t))\"]\nfrequencies: [2]\n");
  EXPECT_EQ(CountAuxiliaries(r), 1) << Dump(r);
  EXPECT_TRUE(HasEquation(r, "2*exp_1*sin((w) t) + exp_1'")) << Dump(r);
  ExpectPinsHoldAtTheGuess(r);
}

// ---- conditions and guesses ------------------------------------------------------------------
TEST(Recast, VelocityConditionActsOnTheVelocityState) {
  const RecastResult r = RecastText(Free("x'' + x = 0"));
  Eigen::VectorXd z(2), dz(2), gz(2), gdz(2);
  z << 0.7, -0.25;
  dz << 9, 9;
  gz.setZero();
  gdz.setZero();
  // x'(0) = 0 reads x_d1(0), the state holding x'.
  EXPECT_DOUBLE_EQ(r.problem.conditions[1].function(z, dz, &gz, &gdz), -0.25);
  EXPECT_DOUBLE_EQ(gz(1), 1.0);
  EXPECT_DOUBLE_EQ(gdz.norm(), 0.0);
  EXPECT_DOUBLE_EQ(r.problem.conditions[0].function(z, dz, &gz, &gdz), 0.7 - 0.5);
}

TEST(Recast, GeneralConditionWithGradient) {
  const RecastResult r = RecastText(
      "variables: [x]\nequations: [\"x'' + x = 0\"]\nfrequencies: [{guess: 1}]\n"
      "conditions: [\"x(0)^2 + x'(0)^2 = 1\"]\n");
  Eigen::VectorXd z(2), dz(2), gz(2), gdz(2);
  z << 0.6, 0.5;
  dz.setZero();
  gz.setZero();
  gdz.setZero();
  EXPECT_NEAR(r.problem.conditions[0].function(z, dz, &gz, &gdz), 0.36 + 0.25 - 1, 1e-15);
  EXPECT_NEAR(gz(0), 1.2, 1e-15);
  EXPECT_NEAR(gz(1), 1.0, 1e-15);
}

TEST(Recast, GuessOfAuxiliariesFollowsTheirDefinitions) {
  const RecastResult r = RecastText(Free("x'' + x/sqrt(1 + x^2) + exp(x) - 1 = 0"));
  const std::vector<double> theta{0.3};
  const Eigen::VectorXd g = r.guess(theta);
  const double x = 0.5 * std::cos(0.3), v = -0.5 * std::sin(0.3);  // A cos(w t), w = 1
  const auto names = Names(r);
  for (std::size_t j = 0; j < names.size(); ++j) {
    double expected = 0;
    if (names[j] == "x") expected = x;
    else if (names[j] == "x_d1") expected = v;
    else if (names[j] == "sqrt_1") expected = std::sqrt(1 + x * x);
    else if (names[j] == "inv_sqrt_1") expected = 1 / std::sqrt(1 + x * x);
    else if (names[j] == "exp_x") expected = std::exp(x);
    else ADD_FAILURE() << "unexpected variable " << names[j] << "\n" << Dump(r);
    EXPECT_NEAR(g(j), expected, 1e-15) << names[j];
  }
}

TEST(Recast, InitialStateFromConditionsWhenNotGiven) {
  const RecastResult r = RecastText(Free("x'' + x = 0"));
  ASSERT_TRUE(r.initial_state.has_value());
  EXPECT_EQ(*r.initial_state, (std::vector<double>{0.5, 0.0}));
}

TEST(Recast, ParameterOverridesApply) {
  const RecastResult r = RecastText(Free("x'' + x = 0"), {{"A", 2.0}});
  EXPECT_DOUBLE_EQ(r.parameters.at("A"), 2.0);
  EXPECT_EQ(*r.initial_state, (std::vector<double>{2.0, 0.0}));
}

TEST(Recast, ReproducibleWhateverRanBefore) {
  // GiNaC orders sums by hash values of symbols, which depend on how many
  // symbols the process created before; the recast must not.
  const std::string text = Free(
      "x'' + log(1 + x) + asin(x/2) + acos(x/3) + atan(x) + x/sqrt(1 + x^2) + exp(-x) + "
      "1/(1 + sin(x)^2) + cosh(x'/4) - 1 + x^0.3 = 0");
  const std::string first = RecastText(text).Report();
  for (int i = 0; i < 7; ++i) RecastText(Free("x'' + sin(x)*exp(x') + tanh(x) = 0"));
  EXPECT_EQ(RecastText(text).Report(), first);
}

TEST(Recast, ReportShowsDefinitionsEquationsAndDegree) {
  const RecastResult r = RecastText(Free("x'' + sin(x) = 0"));
  const std::string report = r.Report();
  EXPECT_NE(report.find("sin_x = sin(x)"), std::string::npos) << report;
  EXPECT_NE(report.find("degree phi = 2"), std::string::npos) << report;
  EXPECT_NE(report.find("pin cos_x(0) = cos(x)"), std::string::npos) << report;
}

}  // namespace
}  // namespace rmhb::model

namespace rmhb::model {
namespace {

// variables_from_user: states read off the user values, auxiliaries from
// their definitions, including one of the top derivative (sin(x') needs x'').
TEST(Recast, VariablesFromUserValues) {
  const RecastResult r = RecastText(
      "variables: [theta]\nparameters: {theta0: 1.5}\nequations: [\"theta'' + sin(theta) = 0\"]\n"
      "frequencies: [{guess: 0.86}]\nconditions: [\"theta(0) = theta0\", \"theta'(0) = 0\"]\n");
  ASSERT_EQ(r.user_derivatives, std::vector<int>{2});  // theta, theta', theta''
  const Eigen::VectorXd z = r.variables_from_user({0.0}, {0.7, -0.3, -std::sin(0.7)});
  ASSERT_EQ(z.size(), 4);
  EXPECT_EQ(z(0), 0.7);
  EXPECT_EQ(z(1), -0.3);
  EXPECT_NEAR(z(2), std::sin(0.7), 1e-15);
  EXPECT_NEAR(z(3), std::cos(0.7), 1e-15);
  const RecastResult top = RecastText(
      "variables: [x]\nequations: [\"x' + x + sin(x')/10 = cos(w*t)\"]\nfrequencies: [1]\n");
  ASSERT_EQ(top.user_derivatives, std::vector<int>{2});  // x, x', x''
  const Eigen::VectorXd y = top.variables_from_user({0.0}, {0.1, 0.4, 2.0});
  EXPECT_EQ(y(1), 0.4);  // x_d1 = x'
  EXPECT_NEAR(y(2), std::sin(0.4), 1e-15);
  EXPECT_THROW(top.variables_from_user({0.0}, {0.1, 0.4}), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb::model

// Every recast rule end to end: a periodic problem built on it, recast,
// solved by SolveHarmonicBalance, compared with an independent reference
// (exact quadrature of the period, or published exact values). Required:
// frequency error <= 1e-11.

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "rmhb/harmonic_balance.h"
#include "rmhb/model/recast.h"
#include "tests/model/period_quadrature.h"

namespace rmhb::model {
namespace {

using rmhb::testing::Real;

struct FreeCase {
  std::string equation;  // in x
  double amplitude;      // x(0) = A, x'(0) = 0
  std::function<Real(Real)> force;  // x'' + force(x) = 0 (for the reference)
  int degree;                       // expected phi
  int order = 30;
};

std::string FreeModel(const FreeCase& c, double w_guess) {
  char buffer[1024];
  std::snprintf(buffer, sizeof(buffer),
                "variables: [x]\n"
                "parameters: {A: %.17g}\n"
                "equations: [\"%s\"]\n"
                "frequencies: [{guess: %.17g}]\n"
                "conditions: [\"x(0) = A\", \"x'(0) = 0\"]\n"
                "guess: {x: \"A*cos(w*t)\"}\n",
                c.amplitude, c.equation.c_str(), w_guess);
  return buffer;
}

struct Outcome {
  double omega = 0;
  double x_half = 0;  // x at half period
  bool converged = false;
  int degree = 0;
  std::string report;
};

Outcome SolveFree(const FreeCase& c, double w_guess) {
  const ModelDefinition m = ParseModel(FreeModel(c, w_guess), "case.yaml");
  const RecastResult r = Recast(m);
  HarmonicBalanceOptions options;
  options.order = c.order;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(r.problem, r.InitialGuess(c.order), options);
  Outcome o;
  o.degree = r.degree;
  o.converged = s.converged();
  o.report = r.Report() + s.FullReport();
  if (!s.solution) return o;
  o.omega = s.solution->frequencies()[0];
  o.x_half = s.solution->Value(0, M_PI / o.omega);
  return o;
}

void CheckFree(const FreeCase& c) {
  const rmhb::testing::Oscillation ref = rmhb::testing::ConservativeOscillation(c.force, c.amplitude);
  const double omega = static_cast<double>(ref.omega());
  const Outcome o = SolveFree(c, omega * 1.02);  // start 2 % off
  ASSERT_TRUE(o.converged) << o.report;
  EXPECT_EQ(o.degree, c.degree) << o.report;
  const double error = std::abs(o.omega - omega);
  const double x_error = std::abs(o.x_half - static_cast<double>(ref.x_min));
  std::printf("  %-36s phi %d  N %d  omega %.15f  |d omega| %.2e  |d x_min| %.2e\n",
              c.equation.c_str(), o.degree, c.order, o.omega, error, x_error);
  EXPECT_LE(error, 1e-11) << o.report;
  EXPECT_LE(x_error, 1e-11) << o.report;
}

// ---- the quadrature itself against the exact pendulum value -----------------
TEST(PeriodQuadrature, ReproducesTheExactPendulumFrequency) {
  auto ref = rmhb::testing::ConservativeOscillation([](Real x) { return std::sin(x); }, 1.5L);
  EXPECT_NEAR(static_cast<double>(ref.omega()), 0.860608346679612985103549304862, 1e-16);
  EXPECT_NEAR(static_cast<double>(ref.x_min), -1.5, 1e-16);
}

// ---- appendix rows ---------------------------------------------------------------
TEST(RecastSolve, SinCosPendulum) {
  CheckFree({"x'' + sin(x) = 0", 1.5, [](Real x) { return std::sin(x); }, 2, 25});
}

TEST(RecastSolve, Exp) {
  CheckFree({"x'' + exp(x) - 1 = 0", 1.0, [](Real x) { return std::exp(x) - 1; }, 2, 30});
}

TEST(RecastSolve, Log) {
  CheckFree({"x'' + log(1 + x) = 0", 0.5, [](Real x) { return std::log1p(x); }, 2, 30});
}

TEST(RecastSolve, LogWithBase) {
  CheckFree({"x'' + log(2 + x, 2) - 1 = 0", 0.8,
             [](Real x) { return std::log2(2 + x) - 1; }, 2, 30});
}

TEST(RecastSolve, Tan) {
  CheckFree({"x'' + tan(x) = 0", 1.0, [](Real x) { return std::tan(x); }, 3, 30});
}

TEST(RecastSolve, Asin) {
  CheckFree({"x'' + asin(x/2) = 0", 1.0, [](Real x) { return std::asin(x / 2); }, 2, 30});
}

TEST(RecastSolve, Acos) {
  CheckFree({"x'' + x*acos(x/2) = 0", 1.0, [](Real x) { return x * std::acos(x / 2); }, 2, 30});
}

TEST(RecastSolve, Atan) {
  CheckFree({"x'' + atan(x) = 0", 1.2, [](Real x) { return std::atan(x); }, 2, 36});
}

TEST(RecastSolve, Sinh) {
  CheckFree({"x'' + sinh(x) = 0", 1.5, [](Real x) { return std::sinh(x); }, 2, 30});
}

TEST(RecastSolve, Cosh) {
  CheckFree({"x'' + x*cosh(x) = 0", 1.0, [](Real x) { return x * std::cosh(x); }, 2, 30});
}

TEST(RecastSolve, Tanh) {
  CheckFree({"x'' + tanh(x) = 0", 1.2, [](Real x) { return std::tanh(x); }, 3, 30});
}

// ---- algebraic recasts ---------------------------------------------------------------
TEST(RecastSolve, Rational) {
  CheckFree({"x'' + x/(1 + x^2) = 0", 1.0, [](Real x) { return x / (1 + x * x); }, 2, 30});
}

TEST(RecastSolve, Radical) {
  CheckFree({"x'' + x/sqrt(1 + x^2) = 0", 1.5, [](Real x) { return x / std::sqrt(1 + x * x); },
             2, 30});
}

TEST(RecastSolve, RealPower) {
  // 0.3 = 3/10: beyond the root rule, through u' = n g' u / g.
  CheckFree({"x'' + x*(1 + x^2)^0.3 = 0", 1.0,
             [](Real x) { return x * std::pow(1 + x * x, 0.3L); }, 4, 30});
}

// ---- nested compositions -------------------------------------------------------------
TEST(RecastSolve, SinOfExp) {
  CheckFree({"x'' + sin(exp(x) - 1) = 0", 0.8, [](Real x) { return std::sin(std::exp(x) - 1); },
             2, 35});
}

TEST(RecastSolve, RationalOfSin) {
  CheckFree({"x'' + x/(1 + sin(x)^2) = 0", 1.0,
             [](Real x) { return x / (1 + std::sin(x) * std::sin(x)); }, 2, 30});
}

// ---- derivative coupling, second derivative inside a nonlinear term --------------------
TEST(RecastSolve, PositionDependentMass) {
  // (1 + x^2) x'' + x x'^2 + x = 0: Lagrangian (1 + x^2) x'^2/2 - x^2/2, energy
  // (1 + x^2) x'^2/2 + x^2/2, so T = 4 integral_0^{pi/2} sqrt(1 + A^2 sin^2 phi).
  const Real A = 1;
  rmhb::testing::GaussLegendre rule(64);
  const Real T = 4 * rule.Integrate([&](Real p) { return std::sqrt(1 + A * A * std::sin(p) * std::sin(p)); },
                                    0, 3.141592653589793238462643383279502884L / 2);
  const double omega = static_cast<double>(2 * 3.141592653589793238462643383279502884L / T);
  FreeCase c{"x'' + x^2*x'' + x*x'^2 + x = 0", 1.0, nullptr, 3, 40};
  const Outcome o = SolveFree(c, omega * 1.02);
  ASSERT_TRUE(o.converged) << o.report;
  EXPECT_EQ(o.degree, 3);
  std::printf("  %-36s phi %d  N %d  omega %.15f  |d omega| %.2e\n", c.equation.c_str(), o.degree,
              c.order, o.omega, std::abs(o.omega - omega));
  EXPECT_LE(std::abs(o.omega - omega), 1e-11) << o.report;
  EXPECT_LE(std::abs(o.x_half + 1.0), 1e-11) << o.report;
}

// ---- radical of the velocity: the relativistic oscillator (rmhb/METHOD.md eq. 17) ----------
TEST(RecastSolve, RelativisticOscillator) {
  const char* text =
      "variables: [x]\n"
      "parameters: {beta: 0.85}\n"
      "equations: [\"x'' + (1 - x'^2)^(3/2)*x = 0\"]\n"
      "frequencies: [{guess: 0.75}]\n"
      "conditions: [\"x(0) = 0\", \"x'(0) = beta\"]\n"
      "guess: {x: \"beta/w*sin(w*t)\"}\n";
  const RecastResult r = Recast(ParseModel(text, "relativistic.yaml"));
  EXPECT_EQ(r.degree, 4);
  HarmonicBalanceOptions options;
  options.order = 60;
  const auto s = SolveHarmonicBalance(r.problem, r.InitialGuess(options.order), options);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  const double omega = s.solution->frequencies()[0];
  const double amplitude = s.solution->Value(0, M_PI / (2 * omega));
  const double omega_ref = 0.769790190987922482444839653363;
  const double amplitude_ref = 1.34038501297574794295514979307;
  std::printf("  relativistic beta 0.85  N %d  |d omega| %.2e  |d A| %.2e\n", options.order,
              std::abs(omega - omega_ref), std::abs(amplitude - amplitude_ref));
  EXPECT_LE(std::abs(omega - omega_ref), 1e-11);
  EXPECT_LE(std::abs(amplitude - amplitude_ref), 1e-11);
}

// ---- forced problems: the original equation checked pointwise on the solution --------
// max over t of |residual of the ORIGINAL equation| evaluated with x, x', x''
// of the harmonic balance solution (variable 0 is x, variable 1 x' when the
// chain has it; x'' is the derivative of x').
double MaxOriginalResidual(const HarmonicSolution& s, double t_end,
                           const std::function<double(double t, double x, double v, double a)>& g,
                           bool first_order = false) {
  double worst = 0;
  for (int i = 0; i <= 400; ++i) {
    const double t = t_end * i / 400;
    const double x = s.Value(0, t);
    const double v = first_order ? s.Derivative(0, t) : s.Value(1, t);
    const double a = first_order ? 0.0 : s.Derivative(1, t);
    worst = std::max(worst, std::abs(g(t, x, v, a)));
  }
  return worst;
}

HarmonicBalanceSummary SolveText(const std::string& text, int order, RecastResult* recast) {
  *recast = Recast(ParseModel(text, "case.yaml"));
  HarmonicBalanceOptions options;
  options.order = order;
  return SolveHarmonicBalance(recast->problem, recast->InitialGuess(order), options);
}

TEST(RecastSolve, TranscendentalOfTheTopDerivative) {
  // x' + x + sin(x')/10 = cos(t): sin(x') needs x'', so the chain grows and
  // x' becomes a state; the equation is implicit in x'.
  RecastResult r;
  const auto s = SolveText(
      "variables: [x]\nequations: [\"x' + x + sin(x')/10 = cos(w*t)\"]\nfrequencies: [1]\n"
      "guess: {x: \"sin(w*t)/2\"}\n",
      30, &r);
  ASSERT_TRUE(s.converged()) << s.FullReport() << r.Report();
  const double residual = MaxOriginalResidual(*s.solution, 2 * M_PI, [](double t, double x, double v, double) {
    return v + x + std::sin(v) / 10 - std::cos(t);
  });
  std::printf("  x' + x + sin(x')/10 = cos t: max |original residual| %.2e\n", residual);
  EXPECT_LE(residual, 1e-12);
}

TEST(RecastSolve, NonlinearFunctionsOfTheForcing) {
  // A Hill equation with exp(cos t) and a rational forcing 1/(2 + cos t).
  RecastResult r;
  const auto s = SolveText(
      "variables: [x]\nequations: [\"x'' + x'/5 + (2 + exp(cos(w*t))/4)*x = 1/(2 + cos(w*t))\"]\n"
      "frequencies: [1]\n",
      30, &r);
  ASSERT_TRUE(s.converged()) << s.FullReport() << r.Report();
  const double residual = MaxOriginalResidual(*s.solution, 2 * M_PI, [](double t, double x, double v, double a) {
    return a + v / 5 + (2 + std::exp(std::cos(t)) / 4) * x - 1 / (2 + std::cos(t));
  });
  std::printf("  Hill equation with exp(cos t): max |original residual| %.2e\n", residual);
  EXPECT_LE(residual, 1e-12);
}

TEST(RecastSolve, QuasiPeriodicForcingOnTwoKnownBases) {
  // Duffing forced at two incommensurate frequencies: the response lives on
  // the 2-torus; forcing terms map to Cos({1,0}), Cos({0,1}).
  RecastResult r;
  const auto s = SolveText(
      "variables: [x]\nparameters: {F: 0.3}\n"
      "equations: [\"x'' + x'/5 + x + x^3/10 = F*cos(w1*t) + F*cos(w2*t)\"]\n"
      "frequencies: [1.3, 1.7320508075688772]\n",
      12, &r);
  ASSERT_TRUE(s.converged()) << s.FullReport() << r.Report();
  const double residual = MaxOriginalResidual(*s.solution, 40, [](double t, double x, double v, double a) {
    return a + v / 5 + x + x * x * x / 10 - 0.3 * std::cos(1.3 * t) -
           0.3 * std::cos(1.7320508075688772 * t);
  });
  std::printf("  two-frequency Duffing p 12: max |original residual| over t in [0, 40] %.2e\n", residual);
  EXPECT_LE(residual, 1e-10);
}

}  // namespace
}  // namespace rmhb::model

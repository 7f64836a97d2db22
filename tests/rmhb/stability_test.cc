// Stability three ways: Hill's method on the harmonic balance Jacobian
// (rmhb/hill_stability.h), the monodromy of the same linearisation
// integrated in the time domain (rmhb/harmonic_monodromy.h) and the
// monodromy matrix of a CVODE integration of the original equations
// (integrators/floquet.h), on the
// forced Duffing oscillator with three coexisting periodic solutions. Both
// are also held against Liouville's formula: for x'' + c x' + k x + a x^3 =
// F cos(w t) the trace of the Jacobian is -c, so mu_1 mu_2 = exp(-c T) exactly.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "examples/example_system.h"
#include "integrators/floquet.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/harmonic_monodromy.h"
#include "rmhb/hill_stability.h"

namespace rmhb {
namespace {

constexpr double kC = 0.1, kW = 2.0;

struct Branch {
  HarmonicSolution solution;
  HillStabilityReport hill;
  integrators::FloquetReport floquet;
  MonodromyResult linearised;  // HarmonicMonodromy
};

// Largest distance from each multiplier of `a` to the nearest of `b`.
double Nearest(const std::vector<std::complex<double>>& a, const std::vector<std::complex<double>>& b) {
  double worst = 0;
  for (const auto& mu : a) {
    double nearest = HUGE_VAL;
    for (const auto& nu : b) nearest = std::min(nearest, std::abs(mu - nu));
    worst = std::max(worst, nearest);
  }
  return worst;
}

// The three solutions at w = 2 (c = 0.1, k = a = F = 1), from the roots y = A^2
// of the one-harmonic amplitude equation ((k - w^2 + 3/4 a y)^2 + c^2 w^2) y = F^2.
std::vector<Branch> ThreeBranches() {
  const examples::ExampleSetup e = examples::BuildExample("duffing", {{"w", kW}, {"c", kC}});
  auto f = [](double y) {
    const double K = 1 - kW * kW + 0.75 * y;
    return (K * K + kC * kC * kW * kW) * y - 1;
  };
  std::vector<Branch> branches;
  for (int i = 0; i < 6000; ++i) {
    double lo = i * 1e-3, hi = lo + 1e-3;
    if (f(lo) * f(hi) > 0) continue;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (f(lo) * f(mid) <= 0 ? hi : lo) = mid;
    }
    const double y = 0.5 * (lo + hi), K = 1 - kW * kW + 0.75 * y, D = K * K + kC * kC * kW * kW;
    Eigen::MatrixXd g = Eigen::MatrixXd::Zero(2, 3);
    g(0, 1) = K / D;
    g(0, 2) = kC * kW / D;
    g(1, 1) = kW * g(0, 2);
    g(1, 2) = -kW * g(0, 1);
    HarmonicBalanceOptions options;
    options.order = 20;
    const HarmonicBalanceSummary s = SolveHarmonicBalance(
        e.problem, HarmonicSolution(HarmonicBasis::Periodic(1), {kW}, g, e.problem.system.variables()),
        options);
    EXPECT_TRUE(s.converged()) << s.FullReport();
    const HarmonicSolution& sol = *s.solution;
    integrators::OdeSystem ode{2, e.original.rhs};
    branches.push_back({sol, HillStability(e.problem, sol),
                        integrators::FloquetMultipliers(ode, e.original.state(sol, 0.0), 0.0, 2 * M_PI / kW),
                        HarmonicMonodromy(e.problem, sol)});
  }
  return branches;
}

TEST(Stability, HillAndFloquetAgreeOnTheThreeDuffingBranches) {
  const std::vector<Branch> b = ThreeBranches();
  ASSERT_EQ(b.size(), 3u);  // lower, middle, upper by amplitude
  EXPECT_LT(b[0].solution.Amplitude(0), b[1].solution.Amplitude(0));
  EXPECT_LT(b[1].solution.Amplitude(0), b[2].solution.Amplitude(0));
  const double T = 2 * M_PI / kW;
  for (int i = 0; i < 3; ++i) {
    const Branch& r = b[i];
    SCOPED_TRACE("branch " + std::to_string(i) + ": " + r.hill.BriefReport() + "; " + r.floquet.BriefReport());
    ASSERT_TRUE(r.floquet.ok);
    // The solution solves the original equations: the orbit closes.
    EXPECT_LT(r.floquet.closure_error, 1e-9);
    ASSERT_EQ(r.hill.exponents.size(), 2u);
    ASSERT_EQ(r.floquet.multipliers.size(), 2u);
    EXPECT_EQ(r.hill.stable, r.floquet.stable);
    EXPECT_EQ(r.hill.stable, i != 1);  // the middle one is the saddle
    // Liouville: mu_1 mu_2 = exp(-c T), and Re lambda_1 + Re lambda_2 = -c.
    EXPECT_NEAR(std::abs(r.floquet.multipliers[0] * r.floquet.multipliers[1]), std::exp(-kC * T), 1e-9);
    EXPECT_NEAR(std::abs(r.hill.multipliers[0] * r.hill.multipliers[1]), std::exp(-kC * T), 1e-12);
    EXPECT_NEAR(r.hill.exponents[0].real() + r.hill.exponents[1].real(), -kC, 1e-12);
    // The same multipliers, whichever order each method lists a complex pair in.
    for (const auto& mu : r.hill.multipliers) {
      double nearest = HUGE_VAL;
      for (const auto& nu : r.floquet.multipliers) nearest = std::min(nearest, std::abs(mu - nu));
      EXPECT_LT(nearest, 1e-8 * std::max(1.0, std::abs(mu))) << "Hill multiplier " << mu;
    }
  }
  // The linearisation's own monodromy: Hill's multipliers (the same
  // linearisation) to round-off and the extrapolation's tolerance, CVODE's
  // to the truncation at N = 20, and Liouville (the trace of its Jacobian is
  // -c for any x(t), so this checks the integration alone) to 1e-10.
  for (int i = 0; i < 3; ++i) {
    const MonodromyResult& m = b[i].linearised;
    SCOPED_TRACE("branch " + std::to_string(i) + ": " + m.message);
    ASSERT_TRUE(m.ok);
    ASSERT_EQ(m.multipliers.size(), 2u);
    EXPECT_EQ(m.trivial, -1);
    EXPECT_LT(Nearest(m.multipliers, b[i].hill.multipliers), 1e-10);
    EXPECT_LT(Nearest(m.multipliers, b[i].floquet.multipliers), 1e-8);
    EXPECT_NEAR(std::abs(m.multipliers[0] * m.multipliers[1]), std::exp(-kC * T), 1e-10);
  }
  // The saddle has a real multiplier outside the unit circle.
  EXPECT_GT(std::abs(b[1].floquet.multipliers[0]), 1.0);
  EXPECT_NEAR(b[1].floquet.multipliers[0].imag(), 0.0, 1e-12);
}

// A linear oscillator (a = 0) has exact exponents -c/2 +- i sqrt(k - c^2/4),
// whatever the forcing.
TEST(Stability, ExactExponentsOfTheForcedLinearOscillator) {
  const examples::ExampleSetup e = examples::BuildExample("duffing", {{"a", 0.0}, {"c", 0.3}, {"w", 1.3}});
  HarmonicBalanceOptions options;
  options.order = 8;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(e.problem, e.guess, options);
  ASSERT_TRUE(s.converged());
  const HillStabilityReport h = HillStability(e.problem, *s.solution);
  const double T = 2 * M_PI / 1.3;
  const std::complex<double> exact(-0.15, std::sqrt(1 - 0.15 * 0.15));
  ASSERT_EQ(h.exponents.size(), 2u);
  EXPECT_TRUE(h.stable);
  for (const auto& l : h.exponents) {
    // Any copy lambda + i m w is the same exponent; the multiplier is unique.
    const std::complex<double> mu = std::exp(l * T);
    EXPECT_LT(std::min(std::abs(mu - std::exp(exact * T)), std::abs(mu - std::exp(std::conj(exact) * T))), 1e-13)
        << l;
  }
  const integrators::FloquetReport f = integrators::FloquetMultipliers(
      {2, e.original.rhs}, e.original.state(*s.solution, 0.0), 0.0, T);
  for (const auto& mu : f.multipliers)
    EXPECT_LT(std::min(std::abs(mu - std::exp(exact * T)), std::abs(mu - std::exp(std::conj(exact) * T))), 1e-9)
        << mu;
  const MonodromyResult m = HarmonicMonodromy(e.problem, *s.solution);
  ASSERT_TRUE(m.ok) << m.message;
  for (const auto& mu : m.multipliers)
    EXPECT_LT(std::min(std::abs(mu - std::exp(exact * T)), std::abs(mu - std::exp(std::conj(exact) * T))), 1e-12)
        << mu;
  EXPECT_THROW(integrators::FloquetMultipliers({2, e.original.rhs}, Eigen::Vector2d(0, 0), 0.0, 0.0),
               std::invalid_argument);
  EXPECT_THROW(integrators::FloquetMultipliers({2, e.original.rhs}, Eigen::Vector3d(0, 0, 0), 0.0, T),
               std::invalid_argument);
}

// The damped Mathieu equation x'' + c x' + (delta + eps cos t) x = 0 inside its
// first tongue: x = 0 is a periodic solution with real NEGATIVE multipliers,
// whose exponents sigma +- i/2 are equally central copies on the edge of the
// Brillouin zone; Hill must keep two different exponents, not one twice.
TEST(Stability, HillKeepsBothFlipMultipliersOfTheMathieuTongue) {
  const double c = 0.05, delta = 0.25, eps = 0.2;
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("v");
  s.AddEquation(s.D("x") - s.Var("v"));
  s.AddEquation(s.D("v") + c * s.Var("v") + delta * s.Var("x") + Polynomial::Cos({1}, eps) * s.Var("x"));
  const HarmonicBalanceProblem problem{s, {1.0}, {false}, {}};
  const HarmonicSolution zero(HarmonicBasis::Periodic(12), {1.0}, Eigen::MatrixXd::Zero(2, 25), s.variables());
  const HillStabilityReport h = HillStability(problem, zero);
  const integrators::FloquetReport f = integrators::FloquetMultipliers(
      {2, [=](double t, const double* y, double* dy) {
         dy[0] = y[1];
         dy[1] = -c * y[1] - (delta + eps * std::cos(t)) * y[0];
       }},
      Eigen::Vector2d(0, 0), 0.0, 2 * M_PI);
  SCOPED_TRACE(h.BriefReport() + "; " + f.BriefReport());
  ASSERT_EQ(h.multipliers.size(), 2u);
  ASSERT_EQ(f.multipliers.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_LT(f.multipliers[i].real(), 0);
    EXPECT_NEAR(f.multipliers[i].imag(), 0, 1e-12);
    // Both sorted by decreasing real part of lambda = decreasing |mu|.
    EXPECT_NEAR(std::abs(h.multipliers[i] - f.multipliers[i]), 0, 1e-8);
  }
  EXPECT_NEAR((f.multipliers[0] * f.multipliers[1]).real(), std::exp(-c * 2 * M_PI), 1e-9);
  EXPECT_FALSE(h.stable);
  EXPECT_FALSE(f.stable);
  // Both flip multipliers, real and negative, from the linearisation too.
  const MonodromyResult m = HarmonicMonodromy(problem, zero);
  ASSERT_TRUE(m.ok) << m.message;
  EXPECT_LT(Nearest(m.multipliers, f.multipliers), 1e-9);
  for (const auto& mu : m.multipliers) EXPECT_LT(mu.real(), 0);
}

TEST(Stability, HillRefusesPinnedAuxiliariesAndASolutionOnOtherBases) {
  const examples::ExampleSetup p = examples::BuildExample("pendulum");
  EXPECT_THROW(HillStability(p.problem, p.guess), std::invalid_argument);
  const examples::ExampleSetup q = examples::BuildExample("forced-vanderpol");
  EXPECT_THROW(HillStability(q.problem, p.guess), std::invalid_argument);  // a periodic solution, two bases
  // The linearisation's monodromy says why not, and does not throw.
  const MonodromyResult pendulum = HarmonicMonodromy(p.problem, p.guess);
  EXPECT_FALSE(pendulum.ok);
  EXPECT_NE(pendulum.message.find("auxiliaries"), std::string::npos) << pendulum.message;
  const MonodromyResult torus = HarmonicMonodromy(q.problem, q.guess);
  EXPECT_FALSE(torus.ok);
  EXPECT_NE(torus.message.find("periodic"), std::string::npos) << torus.message;
  HarmonicMonodromyOptions bad;
  bad.tolerance = 0;
  EXPECT_THROW(HarmonicMonodromy(p.problem, p.guess, bad), std::invalid_argument);
}

TEST(Stability, FloquetFindsTheTrivialMultiplierOfTheVanDerPolLimitCycle) {
  const examples::ExampleSetup e = examples::BuildExample("vanderpol", {{"eps", 1.0}});
  HarmonicBalanceOptions options;
  options.order = 40;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(e.problem, e.guess, options);
  ASSERT_TRUE(s.converged());
  const HarmonicSolution& sol = *s.solution;
  const double T = 2 * M_PI / sol.frequencies()[0];
  integrators::FloquetOptions fo;
  fo.autonomous = true;
  const integrators::FloquetReport f = integrators::FloquetMultipliers(
      {2, e.original.rhs}, e.original.state(sol, 0.0), 0.0, T, fo);
  const HillStabilityReport h = HillStability(e.problem, sol);
  SCOPED_TRACE(h.BriefReport() + "; " + f.BriefReport());
  ASSERT_TRUE(f.ok);
  ASSERT_GE(f.trivial, 0);
  ASSERT_GE(h.trivial, 0);
  EXPECT_NEAR(std::abs(f.multipliers[f.trivial] - 1.0), 0.0, 1e-8);
  EXPECT_LT(std::abs(h.exponents[h.trivial]), 1e-10);
  EXPECT_TRUE(f.stable);
  EXPECT_TRUE(h.stable);
  // Liouville for x' = u, u' = eps (1 - x^2) u - x: tr J = eps (1 - x^2), so
  // the other multiplier is exp(eps * integral of (1 - x^2) over a period).
  double integral = 0;
  const int m = 4000;
  for (int i = 0; i < m; ++i) {
    const double x = sol.Value(0, T * i / m);
    integral += (1 - x * x) * T / m;  // spectrally accurate for a periodic integrand
  }
  const std::complex<double> other_f = f.multipliers[1 - f.trivial], other_h = h.multipliers[1 - h.trivial];
  EXPECT_NEAR(other_f.real(), std::exp(integral), 1e-8);
  EXPECT_NEAR(other_h.real(), std::exp(integral), 1e-10);
  // The linearisation's monodromy: the trivial multiplier deflated along the
  // flow, and the other by Liouville.
  const MonodromyResult linearised = HarmonicMonodromy(e.problem, sol);
  ASSERT_TRUE(linearised.ok) << linearised.message;
  ASSERT_EQ(linearised.trivial, 0);
  EXPECT_NEAR(std::abs(linearised.multipliers[0] - 1.0), 0.0, 1e-9);
  EXPECT_NEAR(linearised.multipliers[1].real(), std::exp(integral), 1e-10);
  EXPECT_NEAR(linearised.multipliers[1].imag(), 0.0, 1e-12);
}

}  // namespace
}  // namespace rmhb

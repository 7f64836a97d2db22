// Stability two independent ways: Hill's method on the harmonic balance
// Jacobian (rmhb/hill_stability.h) and the monodromy matrix of a CVODE
// integration of the original equations (integrators/floquet.h), on the
// forced Duffing oscillator with three coexisting periodic solutions. Both
// are also held against Liouville's formula: for x'' + c x' + k x + a x^3 =
// F cos(w t) the trace of the Jacobian is -c, so mu_1 mu_2 = exp(-c T) exactly.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "examples/example_system.h"
#include "integrators/floquet.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/hill_stability.h"

namespace rmhb {
namespace {

constexpr double kC = 0.1, kW = 2.0;

struct Branch {
  HarmonicSolution solution;
  HillStabilityReport hill;
  integrators::FloquetReport floquet;
};

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
                        integrators::FloquetMultipliers(ode, e.original.state(sol, 0.0), 0.0, 2 * M_PI / kW)});
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
  // The saddle has a real multiplier outside the unit circle.
  EXPECT_GT(std::abs(b[1].floquet.multipliers[0]), 1.0);
  EXPECT_NEAR(b[1].floquet.multipliers[0].imag(), 0.0, 1e-12);
}

TEST(Stability, HillRefusesPinnedAuxiliariesAndQuasiPeriodicSolutions) {
  const examples::ExampleSetup p = examples::BuildExample("pendulum");
  EXPECT_THROW(HillStability(p.problem, p.guess), std::invalid_argument);
  const examples::ExampleSetup q = examples::BuildExample("forced-vanderpol");
  EXPECT_THROW(HillStability(q.problem, q.guess), std::invalid_argument);
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
}

}  // namespace
}  // namespace rmhb

// Models with algebraic equations: the original equations are a DAE, which
// the integrators layer hands to SUNDIALS IDA. The RHB solution of the
// bundled softening-dae model is checked against two independent references:
// the exact period by energy quadrature, and an IDA integration of the DAE.

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "integrators/ida_integrator.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/model/recast.h"
#include "tests/model/period_quadrature.h"

namespace rmhb::model {
namespace {

RecastResult SofteningDae(double amplitude) {
  return Recast(LoadModelFile("examples/models/softening-dae.yaml"), {{"A", amplitude}});
}

TEST(DaeModel, AlgebraicVariableMakesTheOriginalSystemADae) {
  const RecastResult r = SofteningDae(1.5);
  ASSERT_TRUE(r.original.has_value()) << r.original_error;
  const OriginalSystem& s = *r.original;
  EXPECT_TRUE(s.is_dae());
  EXPECT_FALSE(static_cast<bool>(s.rhs));
  EXPECT_EQ(s.state_names, (std::vector<std::string>{"x", "x'", "z"}));
  EXPECT_EQ(s.differential, (std::vector<bool>{true, true, false}));
  // F(t, y, y') at a consistent point: x = 2, x' = 0.5, z = 1/5, x'' = -2/5.
  const double y[] = {2, 0.5, 0.2}, yp[] = {0.5, -0.4, 123.0};  // z' is not read
  double f[3];
  s.residual(0.0, y, yp, f);
  EXPECT_NEAR(f[0], 0, 1e-15);  // x' - x_d1
  EXPECT_NEAR(f[1], 0, 1e-15);  // x'' + x z
  EXPECT_NEAR(f[2], 0, 1e-15);  // z (1 + x^2) - 1
  const double z_wrong[] = {2, 0.5, 0.3};
  s.residual(0.0, z_wrong, yp, f);
  EXPECT_NEAR(f[2], 0.5, 1e-15);
  // Without an initial value for z the state still comes from initial_state:
  // IDACalcIC computes the algebraic part.
  ASSERT_TRUE(r.initial_state.has_value());
  EXPECT_EQ((*r.initial_state)[0], 1.5);
}

TEST(DaeModel, RhbSolutionAgainstQuadratureAndIda) {
  const double A = 1.5;
  const RecastResult r = SofteningDae(A);
  HarmonicBalanceOptions o;
  o.order = 60;  // the frequency error is 8.5e-11 at N = 30, round-off from N = 50
  const HarmonicBalanceSummary s = SolveHarmonicBalance(r.problem, r.InitialGuess(o.order), o);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  const HarmonicSolution& h = *s.solution;
  const double w = h.frequencies()[0];
  const testing::Real w_exact =
      testing::ConservativeOscillation([](testing::Real x) { return x / (1 + x * x); }, A).omega();
  const double w_error = std::abs(w - static_cast<double>(w_exact));
  EXPECT_LT(w_error, 1e-13);

  const OriginalSystem& original = *r.original;
  const double T = 2 * M_PI / w;
  auto claimed = [&](double t) {
    const std::vector<double> y = original.StateFromSolution(h, t);
    return Eigen::Map<const Eigen::VectorXd>(y.data(), static_cast<long>(y.size())).eval();
  };
  const integrators::ValidationReport v = integrators::ValidateDaeTrajectory(
      integrators::DaeSystem{original.dimension, original.residual, original.differential}, claimed,
      2 * T);
  ASSERT_TRUE(v.ok) << v.message;
  std::printf("  softening-dae A %.1f N %d: |d w| %.1e (quadrature), IDA over 2 T: max error %.1e "
              "at t = %.2f (%.1f ms; solve %.1f ms)\n",
              A, o.order, w_error, v.max_error, v.error_time, v.seconds * 1e3,
              s.solver.seconds * 1e3);
  // IDA's own accuracy, not the solution's: 4.6e-10 or 1.3e-9 on 2001 outputs
  // depending on the last bits of the start (full or condensed layout, which
  // agree to round-off: checked next).
  EXPECT_LT(v.max_error, 3e-9);
  HarmonicBalanceOptions full = o;
  full.condense_definitions = false;
  const HarmonicBalanceSummary f = SolveHarmonicBalance(r.problem, r.InitialGuess(o.order), full);
  ASSERT_TRUE(f.converged()) << f.FullReport();
  EXPECT_NEAR(f.solution->frequencies()[0], w, 1e-14);
  EXPECT_LT((f.solution->coefficients() - h.coefficients()).cwiseAbs().maxCoeff(), 1e-12);

  // IDA started from the model's initial_state with z(0) = 0 and y'(0) = 0,
  // both inconsistent: IDACalcIC repairs them and the trajectory is the RHB one.
  Eigen::VectorXd y0 = Eigen::Map<const Eigen::VectorXd>(r.initial_state->data(), 3);
  y0[2] = 0;
  integrators::IntegratorOptions io;
  io.relative_tolerance = 1e-14;
  io.absolute_tolerance = 1e-16;
  const integrators::IntegrationResult run = integrators::IntegrateDae(
      integrators::DaeSystem{original.dimension, original.residual, original.differential}, y0,
      Eigen::VectorXd::Zero(3), 0.0, {0.0, T / 4, T / 2, T}, io);
  ASSERT_TRUE(run.ok()) << run.message;
  EXPECT_NEAR(run.trajectory.states(0, 2), 1 / (1 + A * A), 1e-14);  // z(0) repaired
  for (int i = 1; i < 4; ++i)
    EXPECT_LT((run.trajectory.states.row(i).transpose() - claimed(run.trajectory.times[i]))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-10);
}

}  // namespace
}  // namespace rmhb::model

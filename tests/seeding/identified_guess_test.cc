// Harmonic balance seeded from frequency identification ONLY: the record is
// a CVODE trajectory of the original equations, the model's frequencies are
// rough values not taken from the example's simulated guess, and the solve
// must land on the solution the example's own guess gives (the existing
// quasi-periodic tests' solution), with the identified bases within 1e-9 of
// the solved frequencies.

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <vector>

#include "examples/example_system.h"
#include "examples/references.h"
#include "rmhb/seeding/identified_guess.h"
#include "frequency_id/frequency_identification.h"
#include "integrators/cvode_integrator.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/symmetry.h"

namespace rmhb::seeding {
namespace {

using examples::BuildExample;
using examples::ExampleSetup;

// The example's problem with the symmetries of its equations that its
// guess has, solved on the adaptive index set to 1e-10 (rmhb solve's
// defaults, METHOD.md s.8).
HarmonicBalanceProblem Symmetric(const ExampleSetup& e) {
  HarmonicBalanceProblem problem = e.problem;
  problem.symmetries =
      SymmetriesOf(e.guess, DetectHalfTurnSymmetries(problem.system, static_cast<int>(problem.frequencies.size())));
  return problem;
}

HarmonicBalanceOptions Adaptive(const ExampleSetup& e) {
  HarmonicBalanceOptions o;
  o.order = e.default_order;
  o.shape = BasisShape::kAdaptive;
  o.tolerance = 1e-10;
  return o;
}

// A fixed index set (the one the adaptive solve chose).
HarmonicBalanceOptions On(const HarmonicBasis& basis) {
  HarmonicBalanceOptions o;
  o.order = basis.order();
  o.basis_for_order = [basis](int) { return basis; };
  return o;
}

// Trajectory from the example's initial state, then identification with the
// settings of `rmhb analyze`.
frequency_id::IdentificationSummary Identify(const ExampleSetup& e, const HarmonicBalanceProblem& problem,
                                             int samples_per_period, double transient,
                                             frequency_id::Signal* record_out = nullptr) {
  RecordOptions record = DefaultRecord(problem.frequencies, samples_per_period);
  record.t_end += transient - record.transient;
  record.transient = transient;
  const frequency_id::Signal signal =
      RecordTrajectory({e.original.dimension(), e.original.rhs}, e.original.initial_state, record);
  frequency_id::IdentificationOptions options;
  options.relative_threshold = 1e-8;
  options.max_components = 32;
  for (size_t b = 0; b < problem.frequencies.size(); ++b)
    if (!problem.unknown_frequency[b]) options.bases.known_frequencies.push_back(problem.frequencies[b]);
  frequency_id::IdentificationSummary summary;
  IdentifyFrequencies(options, signal, &summary);
  if (record_out) *record_out = signal;
  return summary;
}

StateToVariables Variables(const ExampleSetup& e) {
  return [&e](const std::vector<double>&, const std::vector<Eigen::VectorXd>& y) {
    return e.original.variables ? e.original.variables(y[0]) : y[0];
  };
}

TEST(IdentifiedGuess, AsymmetricPendulumBothBasesUnknown) {
  const ExampleSetup e = BuildExample("asym-pendulum");
  const HarmonicBalanceSummary reference = SolveHarmonicBalance(Symmetric(e), e.guess, Adaptive(e));
  ASSERT_TRUE(reference.converged());
  const std::vector<double>& w = reference.solution->frequencies();
  const HarmonicBasis& basis = reference.solution->basis();

  // The paper's FFT estimates: off in the 4th digit, they only size the
  // record and pick the coordinates (the identification finds (beat, w1)).
  HarmonicBalanceProblem problem = Symmetric(e);
  problem.frequencies = {0.9857, 0.9935};
  // Conservative and started on the conditions: no transient.
  const frequency_id::IdentificationSummary id = Identify(e, problem, 12, 0.0);
  ASSERT_TRUE(id.IsUsable()) << id.FullReport();
  const IdentifiedGuess seed = GuessFromIdentification(id, problem, basis, Variables(e));
  EXPECT_NEAR(seed.frequencies[0], w[0], 1e-9);  // measured 1e-11
  EXPECT_NEAR(seed.frequencies[1], w[1], 1e-9);  // measured 2e-12
  EXPECT_GT(seed.energy_on_basis, 0.999999);
  EXPECT_LT(seed.condition_residual, 1e-4);       // the basis's truncation, ~1e-6

  problem.frequencies = seed.frequencies;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(problem, seed.guess, On(basis));
  ASSERT_TRUE(s.converged()) << s.FullReport();
  EXPECT_LE(s.solver.iterations, 4);
  EXPECT_NEAR(s.solution->frequencies()[0], w[0], 1e-12);
  EXPECT_NEAR(s.solution->frequencies()[1], w[1], 1e-12);
  // The conditions fix the phases: the same coefficients, not just the same torus.
  EXPECT_LT((s.solution->coefficients() - reference.solution->coefficients()).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(IdentifiedGuess, ForcedVanDerPolLimitCycleFrequencyUnknown) {
  const ExampleSetup e = BuildExample("forced-vanderpol");
  const HarmonicBalanceSummary reference = SolveHarmonicBalance(Symmetric(e), e.guess, Adaptive(e));
  ASSERT_TRUE(reference.converged());
  const std::vector<double>& w = reference.solution->frequencies();
  const HarmonicBasis& basis = reference.solution->basis();

  HarmonicBalanceProblem problem = Symmetric(e);
  problem.frequencies[1] = 1.0;  // the free oscillator's linear frequency, not the simulated one
  // The torus attracts at rate ~eps/2 = 0.1: 300 time units leave e^-30.
  const frequency_id::IdentificationSummary id = Identify(e, problem, 12, 300.0);
  ASSERT_TRUE(id.IsUsable()) << id.FullReport();
  const IdentifiedGuess seed = GuessFromIdentification(id, problem, basis, Variables(e));
  EXPECT_EQ(seed.frequencies[0], 2.3);
  EXPECT_NEAR(seed.frequencies[1], w[1], 1e-9);  // measured 1e-13
  EXPECT_EQ(seed.phase_shift[0], 0.0);           // the forcing's angle is not free
  EXPECT_LT(seed.condition_residual, 1e-10);     // x'(0) = 0 met by turning theta_2

  problem.frequencies = seed.frequencies;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(problem, seed.guess, On(basis));
  ASSERT_TRUE(s.converged()) << s.FullReport();
  const HarmonicSolution& sol = *s.solution;
  EXPECT_NEAR(sol.frequencies()[1], w[1], 1e-12);
  EXPECT_NEAR(sol.Derivative(0, 0.0), 0.0, 1e-12);
  // x'(0) = 0 has two roots on the torus (x at a maximum or a minimum along
  // theta_2); either is the same torus: the same amplitude per harmonic.
  const Eigen::MatrixXd& a = sol.coefficients();
  const Eigen::MatrixXd& b = reference.solution->coefficients();
  for (int k = 1; k < sol.basis().size(); ++k)
    EXPECT_NEAR(std::hypot(a(0, 2 * k - 1), a(0, 2 * k)), std::hypot(b(0, 2 * k - 1), b(0, 2 * k)), 1e-11)
        << "harmonic " << k;
  const auto v = integrators::ValidateTrajectory(
      {2, e.original.rhs}, [&](double t) { return e.original.state(sol, t); }, 200.0, false);
  ASSERT_TRUE(v.ok) << v.message;
  EXPECT_LT(v.max_error, 1e-8);  // measured 6e-10
}

// One base, and auxiliaries (s = sin(theta), c = cos(theta)) from their
// definitions on the reconstructed state: against the exact frequency.
TEST(IdentifiedGuess, PendulumAuxiliariesFromTheirDefinitions) {
  const ExampleSetup e = BuildExample("pendulum");
  HarmonicBalanceProblem problem = e.problem;
  problem.frequencies = {1.0};
  frequency_id::Signal record;
  const frequency_id::IdentificationSummary id = Identify(e, problem, 64, 0.0, &record);
  ASSERT_TRUE(id.IsUsable()) << id.FullReport();
  // From the lines, then from every harmonic fitted on the record.
  const std::vector<const frequency_id::Signal*> fits = {nullptr, &record};
  for (const frequency_id::Signal* fit : fits) {
    const IdentifiedGuess seed =
        GuessFromIdentification(id, problem, HarmonicBasis::Periodic(25), Variables(e), 0, fit);
    EXPECT_EQ(seed.fitted_harmonics > 6, fit != nullptr);  // 6 lines above 1e-8
    EXPECT_NEAR(seed.frequencies[0], e.reference.frequency, 1e-9);  // CVODE's drift, measured 3e-11
    const int s_index = seed.guess.IndexOf("s");
    EXPECT_NEAR(seed.guess.Value(s_index, 0.0), std::sin(1.5), 1e-8);
    HarmonicBalanceProblem seeded = problem;
    seeded.frequencies = seed.frequencies;
    HarmonicBalanceOptions o;
    o.order = 25;
    const HarmonicBalanceSummary s = SolveHarmonicBalance(seeded, seed.guess, o);
    ASSERT_TRUE(s.converged()) << s.FullReport();
    EXPECT_NEAR(s.solution->frequencies()[0], e.reference.frequency, 1e-14);
  }
}

TEST(IdentifiedGuess, RefusesAnIdentificationWithAnotherNumberOfBases) {
  const ExampleSetup pendulum = BuildExample("pendulum");
  const frequency_id::IdentificationSummary id = Identify(pendulum, pendulum.problem, 64, 0.0);
  ASSERT_TRUE(id.IsUsable());
  const ExampleSetup asym = BuildExample("asym-pendulum");
  try {
    GuessFromIdentification(id, asym.problem, HarmonicBasis::Diamond(2, 2), Variables(asym));
    FAIL() << "no exception";
  } catch (const std::invalid_argument& err) {
    EXPECT_NE(std::string(err.what()).find("found 1 base frequencies, the model has 2"), std::string::npos)
        << err.what();
  }
}

// One period of the exact orbit x = cos t + 0.1 cos 3t of a linear system
// with those two modes (x'' = -x for the first, -9 x for the second, as a
// 4-state ODE): the return to the section is 2 pi to the tolerance, the DFT
// gives both harmonics and nothing else, and the order for 1e-9 is 3.
TEST(OnePeriod, ExactPeriodAndHarmonicsOfAKnownOrbit) {
  integrators::OdeSystem ode{4, [](double, const double* y, double* dy) {
                               dy[0] = y[1], dy[1] = -y[0], dy[2] = y[3], dy[3] = -9 * y[2];
                             }};
  integrators::IntegratorOptions io;
  io.relative_tolerance = 1e-12;
  io.absolute_tolerance = 1e-14;
  const Eigen::Vector4d y0(1, 0, 0.1, 0);
  const std::optional<frequency_id::Signal> period = OnePeriod(ode, y0, 5.0, 6.0, 256, io);
  ASSERT_TRUE(period.has_value());
  EXPECT_NEAR(period->duration(), 2 * M_PI, 1e-10);
  EXPECT_EQ(period->t0, 5.0);
  EXPECT_EQ(PeriodOrder(*period, 1e-9), 3);
  // Sample m is the orbit at m T / 256 from y0.
  for (int m : {0, 37, 200}) {
    const double t = m * period->dt;
    EXPECT_NEAR(period->samples(m, 0) + period->samples(m, 2), std::cos(t) + 0.1 * std::cos(3 * t), 1e-10);
  }
  // Incommensurate modes (-2 instead of -9): the return comes near y0 but
  // not back to it, a torus, no period.
  integrators::OdeSystem torus{4, [](double, const double* y, double* dy) {
                                 dy[0] = y[1], dy[1] = -y[0], dy[2] = y[3], dy[3] = -2 * y[2];
                               }};
  EXPECT_FALSE(OnePeriod(torus, y0, 0.0, 6.0, 256, io).has_value());
  // Far from the guess: no return within 20 % of it.
  EXPECT_FALSE(OnePeriod(ode, y0, 0.0, 3.0, 256, io).has_value());
  EXPECT_THROW(OnePeriod(ode, y0, 0.0, -1.0, 256, io), std::invalid_argument);
}

// Van der Pol at eps = 5 seeded from one exact period of its settled orbit
// and nothing else (no identification: what Analyze falls back on when the
// identification of a relaxation cycle's many lines fails). The seed's
// frequency is the CVODE period's, its phase meets x'(0) = 0, and Newton
// from it converges at order 200 to the period to 1e-10.
TEST(GuessFromPeriod, SeedsAnAutonomousOrbitWithoutIdentification) {
  const ExampleSetup e = BuildExample("vanderpol", {{"eps", 5.0}});
  const integrators::OdeSystem ode{2, e.original.rhs};
  integrators::IntegratorOptions io;
  io.method = integrators::IntegratorOptions::Method::kBdf;
  io.relative_tolerance = 1e-12;
  io.absolute_tolerance = 1e-14;
  const integrators::IntegrationResult settle = integrators::IntegrateOde(ode, Eigen::Vector2d(2, 0), 0, {200.0}, io);
  ASSERT_TRUE(settle.ok());
  const double period = examples::VanDerPolPeriodByCvode(5.0);
  const std::optional<frequency_id::Signal> one =
      OnePeriod(ode, settle.trajectory.states.bottomRows(1).transpose(), 0, 1.1 * period, 4096, io);
  ASSERT_TRUE(one.has_value());
  const HarmonicBasis basis = HarmonicBasis::Periodic(200);
  const IdentifiedGuess seed = GuessFromPeriod(e.problem, basis, Variables(e), 0, *one);
  EXPECT_NEAR(seed.frequencies[0], 2 * M_PI / period, 1e-9);
  EXPECT_GT(seed.period_harmonics, 150);
  EXPECT_LT(seed.condition_residual, 1e-6);
  HarmonicBalanceOptions options;
  options.order = 200;
  HarmonicBalanceProblem problem = e.problem;
  problem.frequencies = seed.frequencies;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(problem, seed.guess, options);
  ASSERT_TRUE(s.converged()) << s.solver.message;
  EXPECT_NEAR(s.solution->frequencies()[0], 2 * M_PI / period, 1e-10);
  // Only for one unknown base.
  const ExampleSetup duffing = BuildExample("duffing");
  EXPECT_THROW(GuessFromPeriod(duffing.problem, HarmonicBasis::Periodic(5), Variables(duffing), 0, *one),
               std::invalid_argument);
}

}  // namespace
}  // namespace rmhb::seeding

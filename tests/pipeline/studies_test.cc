// The studies as a program calls them (rmhb/pipeline/): SolveModel,
// ContinueModel, Identify, Simulate, Census, and the settings they share,
// on model files written for the tests, checked against independent
// references: exact solutions, Abel's formula for the Floquet multipliers,
// CVODE limit-cycle periods.

#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "examples/example_model.h"
#include "rmhb/model/model_error.h"
#include "rmhb/pipeline/branch.h"
#include "rmhb/pipeline/census.h"
#include "rmhb/pipeline/identify.h"
#include "rmhb/pipeline/settings.h"
#include "rmhb/pipeline/simulate.h"
#include "rmhb/pipeline/solve.h"
#include "tests/pipeline/shooting.h"

namespace rmhb {
namespace {

const char* kLinear = "tests/pipeline/models/forced-linear.yaml";
const char* kDuffing = "tests/pipeline/models/forced-duffing.yaml";
const char* kRayleigh = "tests/pipeline/models/quintic-rayleigh.yaml";

// The exact steady-state amplitude of forced-linear.yaml.
double LinearAmplitude(double c, double k, double F, double W) {
  return F / std::hypot(k - W * W, c * W);
}

PreparedSolve Prepared(const std::string& file, const model::ParameterValues& values, int order) {
  SolveSettings settings;
  settings.order = order;
  return PrepareSolve(LoadModel(file, values), settings);
}

TEST(SolveModel, ValidatesAndDecidesStabilityOfTheExactSteadyState) {
  const PreparedSolve p = Prepared(kLinear, {}, 5);
  SolveOptions options;
  options.harmonic_balance = p.options;
  options.validate = true;
  options.validate_periods = 3;
  options.stability = true;
  const SolveSummary s = SolveModel(p.model, p.guess, options);
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  EXPECT_NEAR(s.solution().Amplitude(0), LinearAmplitude(0.1, 1, 0.5, 1.3), 1e-13);
  ASSERT_TRUE(s.validation.has_value());
  EXPECT_STREQ(s.validation->status(), "ok");
  EXPECT_LT(s.validation->verdict.relative_error, 1e-8);
  // Abel: |mu| = exp(-c T / 2) for both multipliers.
  ASSERT_TRUE(s.stability && s.stability->hill && s.stability->floquet);
  const double modulus = std::exp(-0.1 * M_PI / 1.3);
  for (const auto& mu : s.stability->floquet->multipliers) EXPECT_NEAR(std::abs(mu), modulus, 1e-8);
  for (const auto& mu : s.stability->hill->multipliers) EXPECT_NEAR(std::abs(mu), modulus, 1e-8);
  EXPECT_EQ(s.stability->verdict, StabilityVerdict::kStable);

  // The JSON and the text say the same.
  const nlohmann::json j = s.ToJson();
  EXPECT_EQ(j["status"], "converged");
  EXPECT_EQ(j["frequencies"][0].get<double>(), 1.3);
  EXPECT_EQ(j["validation"]["status"], "ok");
  EXPECT_EQ(j["validation"]["max_error"].get<double>(), s.validation->report.max_error);
  EXPECT_EQ(j["stability"]["verdict"], "stable");
  EXPECT_EQ(j["start"], "guess");
  const std::string text = s.FullReport();
  EXPECT_NE(text.find("frequency    1.3"), std::string::npos) << text;
  EXPECT_NE(text.find("validation   ok"), std::string::npos) << text;
  EXPECT_NE(text.find("stability    stable"), std::string::npos) << text;
}

TEST(SolveModel, NonConvergenceIsAStatusAndMisuseThrows) {
  PreparedSolve p = Prepared(kDuffing, {}, 15);
  SolveOptions options;
  options.harmonic_balance = p.options;
  options.harmonic_balance.solver.max_iterations = 1;
  options.harmonic_balance.order_continuation = false;
  options.auto_start = false;
  const SolveSummary s = SolveModel(p.model, p.guess, options);
  EXPECT_EQ(s.status, SolveStatus::kNotConverged);
  EXPECT_GT(s.harmonic_balance.solver.final_residual, 1e-10);
  EXPECT_NE(s.ToJson()["status"], "converged");
  EXPECT_FALSE(s.validation.has_value());

  options.validate_periods = 0;
  EXPECT_THROW(SolveModel(p.model, p.guess, options), std::invalid_argument);
  options = SolveOptions{};
  options.harmonic_balance = p.options;
  options.validate = true;
  p.model.original = nullptr;  // nothing to validate against
  EXPECT_THROW(SolveModel(p.model, p.guess, options), std::invalid_argument);
}

TEST(SolveModel, ABuiltInExampleIsMeasuredAgainstItsExactReference) {
  const Model pendulum = examples::LoadModelOrExample("pendulum");
  EXPECT_FALSE(pendulum.from_file);
  SolveOptions options;
  options.harmonic_balance.order = 25;
  const SolveSummary s = SolveModel(pendulum, options);
  ASSERT_EQ(s.status, SolveStatus::kConverged) << s.FullReport();
  ASSERT_TRUE(s.errors.has_value());
  EXPECT_LT(std::abs(s.errors->frequency), 1e-12);  // elliptic integrals
  EXPECT_EQ(s.ToJson()["reference"]["frequency_error"].get<double>(), s.errors->frequency);
  EXPECT_THROW(examples::LoadModelOrExample("pendulim"), std::invalid_argument);
}

TEST(ContinueModel, EveryPointOfTheLinearResponseIsExactAndValidated) {
  const PreparedSolve p = Prepared(kLinear, {{"W", 0.5}}, 5);
  ContinueOptions options;
  options.parameter = "W";
  options.from = 0.5;
  options.to = 1.5;
  options.steps = 10;
  options.harmonic_balance = p.options;
  options.validate = true;
  const BranchSummary b = ContinueModel(p.model, p.guess, options);
  ASSERT_EQ(b.status, BranchStatus::kCompleted) << b.FullReport();
  ASSERT_GE(b.continuation.points.size(), 8u);
  for (size_t i = 0; i < b.reports.size(); ++i) {
    const double W = b.continuation.points[i].parameter;
    EXPECT_NEAR(b.reports[i].peak, LinearAmplitude(0.1, 1, 0.5, W), 1e-11) << "W = " << W;
    EXPECT_LT(b.reports[i].validation_error, 1e-8) << "W = " << W;
    EXPECT_EQ(b.reports[i].stability, "stable") << "W = " << W;
  }
  EXPECT_TRUE(b.non_physical.empty());
  const nlohmann::json j = b.ToJson();
  EXPECT_EQ(j["points"].get<size_t>(), b.continuation.points.size());
  EXPECT_EQ(j["branch"][0]["amplitude"].get<double>(), b.reports[0].peak);
  EXPECT_TRUE(j["folds"].empty());
}

// `--tol` along a branch: the first point's order meets the target below the
// superharmonic resonances (W = 0.3); as the tail grows past a quarter of the
// target (scaled by the first selection's calibration) the order is selected
// again there and the trace goes on at the higher order, every point within
// the target of CVODE. (At this branch the first order would also have
// stayed within it, 7.3e-12: the watch is an estimate, conservative here.)
TEST(ContinueModel, TheOrderFollowsTheTargetAlongTheBranch) {
  SolveSettings settings;
  settings.tol = 1e-10;
  const PreparedSolve p = PrepareSolve(LoadModel(kDuffing, {{"W", 0.3}, {"F", 0.5}}), settings);
  ContinueOptions options;
  options.parameter = "W";
  options.from = 0.3;
  options.to = 1.2;
  options.stability = false;
  options.validate = true;
  options.harmonic_balance = p.options;
  const BranchSummary b = ContinueModel(p.model, p.guess, options);
  ASSERT_EQ(b.status, BranchStatus::kCompleted) << b.FullReport();
  ASSERT_GE(b.order_raises.size(), 1u) << b.FullReport();
  const BranchSummary::Enrichment& raise = b.order_raises[0];
  std::printf("order raised at W = %.6f (%d -> %d)\n", raise.parameter, raise.before, raise.after);
  EXPECT_GT(raise.after, raise.before);
  double worst = 0;
  for (const BranchPointReport& r : b.reports) worst = std::max(worst, r.validation_error);
  std::printf("largest validation error over %zu points: %.1e\n", b.reports.size(), worst);
  EXPECT_LT(worst, 1e-10);  // measured 1.0e-11
  EXPECT_EQ(b.ToJson()["order_raises"].size(), b.order_raises.size());
  EXPECT_EQ(b.continuation.points.back().solution.basis().order(), b.order_raises.back().after);
  EXPECT_NE(b.FullReport().find("order raised for the target at W = "), std::string::npos);
}

TEST(ContinueModel, TheHardeningDuffingBranchHasTwoFoldsAndAnUnstableMiddle) {
  const PreparedSolve p = Prepared(kDuffing, {{"W", 0.8}, {"c", 0.15}}, 10);
  ContinueOptions options;
  options.parameter = "W";
  options.from = 0.8;
  options.to = 2.0;
  options.harmonic_balance = p.options;
  const BranchSummary b = ContinueModel(p.model, p.guess, options);
  ASSERT_EQ(b.status, BranchStatus::kCompleted) << b.FullReport();
  int folds = 0, unstable = 0;
  for (size_t i = 0; i < b.reports.size(); ++i) {
    folds += b.continuation.points[i].fold;
    unstable += b.reports[i].stability == "unstable";
  }
  EXPECT_EQ(folds, 2) << b.FullReport();
  EXPECT_GT(unstable, 0) << b.FullReport();
  EXPECT_EQ(b.ToJson()["folds"].size(), 2u);
  // The text marks them.
  EXPECT_NE(b.FullReport().find("<- fold"), std::string::npos);
  EXPECT_EQ(b.FullReport(false).find("<- fold"), std::string::npos);
}

TEST(ContinueModel, ARangeTheModelRefusesIsMisuse) {
  const PreparedSolve p = Prepared(kLinear, {}, 5);
  ContinueOptions options;
  options.parameter = "nope";
  options.harmonic_balance = p.options;
  EXPECT_THROW(ContinueModel(p.model, p.guess, options), model::ModelError);  // file:line of the model
  options.parameter = "w";
  options.from = 1;
  options.to = -1;  // a built-in example refuses a negative frequency
  const Model duffing = examples::ExampleModel("duffing");
  EXPECT_THROW(ContinueModel(duffing, GuessAtOrder(duffing, 5), options), std::invalid_argument);
  options.parameter = "W";
  options.from = options.to = 1;
  EXPECT_THROW(ContinueModel(p.model, p.guess, options), std::invalid_argument);
}

TEST(Identify, AModelsLimitCycleFrequencyAgreesWithItsMeasuredPeriod) {
  const Model model = LoadModel(kRayleigh);
  const IdentifySummary s = Identify(model, IdentifyOptions{});
  ASSERT_TRUE(s.usable()) << s.FullReport();
  const double period = testing::LimitCyclePeriodOf(model);
  EXPECT_NEAR(s.identification.bases[0].frequency, 2 * M_PI / period, 1e-7);
  EXPECT_EQ(s.ToJson()["bases"][0]["frequency"].get<double>(), s.identification.bases[0].frequency);
  EXPECT_NE(s.FullReport().find("trajectory: CVODE"), std::string::npos) << s.FullReport();
}

// The pendulum's own motion over the default 300 periods: CVODE's phase
// drift leaves sidebands near 3e-9 of the fundamental, which identification
// took for the lines of a second base (w2 = -1.7e-10, no_convergence) until
// the model's records were read down to kRecordLineThreshold only. Exact:
// w = pi / (2 K(k)), k = sin(q0 / 2).
TEST(Identify, AConservativeOrbitHasOneBaseDespiteTheIntegratorsDrift) {
  const Model model = LoadModel("tests/pipeline/models/original-pendulum.yaml");
  const IdentifySummary s = Identify(model, IdentifyOptions{});
  ASSERT_EQ(s.identification.status, frequency_id::IdentificationStatus::kSuccess) << s.FullReport();
  ASSERT_EQ(s.identification.bases.size(), 1u);
  // The record's frequency is off the exact one by the integration's drift;
  // the uncertainty says so (the record's halves), not 1e-13.
  const double exact = M_PI / (2 * std::comp_ellint_1(std::sin(0.75)));
  EXPECT_NEAR(s.identification.bases[0].frequency, exact, 1e-9);
  EXPECT_GT(s.identification.bases[0].drift, 0.0);
  EXPECT_LT(std::abs(s.identification.bases[0].frequency - exact), 3 * s.identification.bases[0].uncertainty);
  EXPECT_EQ(s.ToJson()["bases"][0]["drift"].get<double>(), s.identification.bases[0].drift);
}

// Van der Pol at mu = 1.5 sampled 32 times per period: its harmonic 21
// folded back to 11.486, which identification took for a second base. The
// record is now sampled until nothing folds back (RecordUnaliased); its
// frequency against the period CVODE measures between upward crossings.
TEST(Identify, ARelaxationCycleIsSampledSoThatNoHarmonicFoldsBack) {
  const Model model = LoadModel("tests/pipeline/models/relaxation-vdp.yaml");
  const IdentifySummary s = Identify(model, IdentifyOptions{});
  ASSERT_EQ(s.identification.status, frequency_id::IdentificationStatus::kSuccess) << s.FullReport();
  ASSERT_EQ(s.identification.bases.size(), 1u) << s.FullReport();
  EXPECT_TRUE(s.sampling.resolved()) << s.sampling.top_band;
  EXPECT_LT(s.sampling.thinning, kRecordOversampling);  // denser than 32 per period
  EXPECT_EQ(s.signal.dt * s.sampling.oversampling, 2 * M_PI / 0.94 / 32 * s.sampling.thinning);
  const double period = testing::LimitCyclePeriodOf(model);
  EXPECT_NEAR(s.identification.bases[0].frequency, 2 * M_PI / period, 1e-9);
  EXPECT_EQ(s.ToJson()["sampling"]["thinning"].get<int>(), s.sampling.thinning);
}

// A forced Duffing file with damping 0.05: the default transient (a tenth of
// the record) left e^-4 of the start in the record and polishing stopped
// (no_convergence). Recorded from its settled state, every line is a
// harmonic of W, the fundamental's amplitude that of the harmonic balance
// solution's (RHB on the recast, an independent method).
TEST(Identify, AForcedMotionIsRecordedOnceItHasSettled) {
  const Model model = LoadModel("tests/pipeline/models/forced-duffing.yaml");
  const IdentifySummary s = Identify(model, IdentifyOptions{});
  ASSERT_EQ(s.identification.status, frequency_id::IdentificationStatus::kSuccess) << s.FullReport();
  EXPECT_GT(s.settle_periods, 0);
  EXPECT_NE(s.FullReport().find("settled"), std::string::npos);
  const SolveSummary hb = SolveModel(model, SolveOptions{});
  ASSERT_EQ(hb.status, SolveStatus::kConverged) << hb.message;
  const HarmonicSolution& x = *hb.harmonic_balance.solution;
  const double W = model.problem.frequencies[0];
  std::complex<double> sum = 0;
  constexpr int kSamples = 64;
  for (int j = 0; j < kSamples; ++j) {
    const double t = 2 * M_PI / W * j / kSamples;
    sum += x.Value(0, t) * std::exp(std::complex<double>(0, -W * t));
  }
  ASSERT_NEAR(s.identification.components[0].frequency, W, 1e-12);
  EXPECT_NEAR(s.identification.components[0].amplitude(0), 2 * std::abs(sum) / kSamples, 1e-8);
}

TEST(Identify, ASampledTwoToneSignalAndARecordCutTooShort) {
  frequency_id::Signal signal;
  signal.t0 = 0;
  signal.dt = 0.05;
  signal.samples.resize(8000, 1);
  for (int i = 0; i < 8000; ++i)
    signal.samples(i, 0) = std::cos(1.3 * i * signal.dt) + 0.5 * std::cos(std::sqrt(5.0) * i * signal.dt + 0.3);
  const IdentifySummary s = Identify(signal, IdentifyOptions{});
  ASSERT_TRUE(s.usable()) << s.FullReport();
  ASSERT_EQ(s.identification.bases.size(), 2u);
  std::vector<double> w = {s.identification.bases[0].frequency, s.identification.bases[1].frequency};
  std::sort(w.begin(), w.end());
  EXPECT_NEAR(w[0], 1.3, 1e-9);
  EXPECT_NEAR(w[1], std::sqrt(5.0), 1e-9);
  IdentifyOptions cut;
  cut.transient = 399;
  EXPECT_THROW(Identify(signal, cut), std::invalid_argument);
}

TEST(Simulate, TheFreeLinearOscillatorFollowsItsExactSolution) {
  // Unforced and undamped from x = 1: x(t) = cos t.
  const Model model = LoadModel(kLinear, {{"F", 0}, {"c", 0}});
  SimulateOptions options;
  options.t_end = 20;
  options.dt = 0.01;
  const SimulateSummary s = Simulate(model, options);
  ASSERT_TRUE(s.ok()) << s.result.message;
  const integrators::Trajectory& tr = s.result.trajectory;
  ASSERT_EQ(tr.size(), 2001);
  double error = 0;
  for (int i = 0; i < tr.size(); ++i) error = std::max(error, std::abs(tr.states(i, 0) - std::cos(tr.times[i])));
  EXPECT_LT(error, 1e-10);
  EXPECT_EQ(s.ToJson()["rows"], 2001);
  options.dt = 0;
  EXPECT_THROW(Simulate(model, options), std::invalid_argument);
}

TEST(Census, RandomStartsOfTheForcedDuffingAreCountedAndChecked) {
  const PreparedSolve p = Prepared(kDuffing, {{"W", 1.5}, {"F", 0.5}}, 3);
  CensusOptions options;
  options.monte_carlo.solve = p.options;
  options.monte_carlo.starts = 40;
  options.monte_carlo.threads = 1;
  const CensusSummary s = Census(p.model, options);
  ASSERT_EQ(s.status, CensusStatus::kCompleted) << s.FullReport();
  const nlohmann::json j = s.ToJson();
  ASSERT_EQ(j["methods"].size(), 2u);
  for (const RuleCensus& r : s.monte_carlo.rules) {
    long counted = 0;
    for (const SolutionCluster& c : r.clusters) {
      counted += c.count;
      // Hill's verdict and the CVODE monodromy matrix's agree on physical solutions.
      if (c.hill && c.original && c.original->ok) {
        EXPECT_EQ(c.hill->stable, c.original->stable);
      }
    }
    EXPECT_EQ(counted, r.converged);
    EXPECT_EQ(r.converged + r.failed, 40);
  }
  options.monte_carlo.starts = 0;
  EXPECT_THROW(Census(p.model, options), std::invalid_argument);
}

TEST(Settings, FrequenciesAndParametersCarryOverToRebuiltModels) {
  SolveSettings settings;
  settings.frequencies = "?1.2";
  settings.order = 10;
  const PreparedSolve p = PrepareSolve(LoadModel(kRayleigh), settings);
  EXPECT_EQ(p.model.problem.frequencies[0], 1.2);
  EXPECT_EQ(p.options.order, 10);
  const Model other = WithParameters(p.model, {{"mu", 0.5}});
  EXPECT_EQ(other.problem.frequencies[0], 1.2);
  EXPECT_EQ(other.overrides.at("mu"), 0.5);
  EXPECT_THROW(WithParameters(p.model, {{"nope", 1}}), std::exception);
  Model bad = LoadModel(kRayleigh);
  EXPECT_THROW(SetFrequencies("1,2", &bad), std::invalid_argument);
  EXPECT_THROW(SetFrequencies("-1", &bad), std::invalid_argument);
  settings.order = 0;
  settings.order_given = true;
  EXPECT_THROW(PrepareSolve(LoadModel(kRayleigh), settings), std::invalid_argument);
  EXPECT_EQ(ParseOverrides({"a=1", "b=2.5", "a=3"}), (std::map<std::string, double>{{"a", 3}, {"b", 2.5}}));
  EXPECT_THROW(ParseAssignment("a=x"), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb

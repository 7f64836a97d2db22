// `rmhb analyze` as a script sees it: the stages of the pipeline in --json,
// exit codes, --frequencies skipping identification, bad input.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>

#include "tests/cli/cli_run.h"

namespace {

using rmhb::testing::Cli;
using rmhb::testing::Json;

// Both bases unknown, identified and then solved: every stage is there, and
// the identified bases agree with the solved ones.
TEST(Analyze, QuasiPeriodicJsonHasEveryStage) {
  const rmhb::testing::CliRun run = Cli("analyze asym-pendulum --json");
  ASSERT_EQ(run.code, 0) << run.out;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["status"], "converged");
  EXPECT_EQ(j["identified"], true);
  for (const char* stage : {"trajectory", "identify", "seed", "solve", "validate"}) {
    ASSERT_TRUE(j["stages"].contains(stage)) << stage;
    EXPECT_GE(j["stages"][stage]["seconds"].get<double>(), 0.0) << stage;
  }
  for (const char* key : {"frequencies", "harmonics", "coefficients", "seconds"}) EXPECT_TRUE(j.contains(key)) << key;
  const auto& bases = j["stages"]["identify"]["bases"];
  ASSERT_EQ(bases.size(), 2u);
  for (int b = 0; b < 2; ++b) {
    EXPECT_LT(std::abs(bases[b]["difference"].get<double>()), 1e-9) << b;  // measured ~1e-11
    EXPECT_EQ(bases[b]["solved"], j["frequencies"][b]);
    EXPECT_EQ(bases[b]["known"], false);
  }
  EXPECT_NEAR(j["frequencies"][0].get<double>(), 0.98512470168, 1e-9);
  EXPECT_NEAR(j["frequencies"][1].get<double>(), 0.99282862390, 1e-9);
  EXPECT_EQ(j["stages"]["solve"]["status"], "converged");
  EXPECT_LT(j["stages"]["solve"]["residual"].get<double>(), 1e-12);
  EXPECT_EQ(j["stages"]["validate"]["status"], "ok");
  EXPECT_LT(j["stages"]["validate"]["max_error"].get<double>(), 1e-8);  // measured 1.6e-9
}

// --frequencies: no trajectory, identification or seed; the model's own
// guess at those frequencies, as `rmhb solve` would.
TEST(Analyze, GivenFrequenciesSkipIdentification) {
  const auto j = Json("analyze forced-vanderpol --frequencies 2.3,?0.9975 --json");
  EXPECT_EQ(j["status"], "converged");
  EXPECT_EQ(j["identified"], false);
  EXPECT_FALSE(j["stages"].contains("trajectory"));
  EXPECT_FALSE(j["stages"].contains("identify"));
  EXPECT_FALSE(j["stages"].contains("seed"));
  EXPECT_TRUE(j["stages"].contains("solve"));
  EXPECT_TRUE(j["stages"].contains("validate"));
  EXPECT_EQ(j["frequencies"][0], 2.3);
  EXPECT_NEAR(j["frequencies"][1].get<double>(), 0.997466254703, 1e-11);
}

// A periodic model file (automatic recast, auxiliaries sin/cos from their
// definitions on the identified signal): one base, against the exact one.
TEST(Analyze, PeriodicModelFileHasOneBase) {
  const auto j = Json("analyze examples/models/pendulum.yaml --json");
  ASSERT_EQ(j["status"], "converged") << j.dump(1);
  ASSERT_EQ(j["stages"]["identify"]["bases"].size(), 1u);
  EXPECT_LT(std::abs(j["stages"]["identify"]["bases"][0]["difference"].get<double>()), 1e-9);
  EXPECT_NEAR(j["frequencies"][0].get<double>(), 0.860608346679612985103549304862, 1e-13);
  EXPECT_TRUE(j["auxiliary_coefficients"].contains("sin_theta"));
  EXPECT_LT(j["stages"]["validate"]["max_error"].get<double>(), 1e-8);
}

// A model with an algebraic equation: the record and the validation come
// from IDA. Reference: the energy quadrature
// T = 4 int_0^A dx / sqrt(log((1 + A^2)/(1 + x^2))), A = 1.5 (mpmath, 30 digits).
TEST(Analyze, DaeModelIsRecordedAndValidatedByIda) {
  const auto j = Json("analyze examples/models/softening-dae.yaml --order 60 --json");
  ASSERT_EQ(j["status"], "converged") << j.dump(1);
  const double w_exact = 0.62103397734533219086635723502;
  EXPECT_NEAR(j["frequencies"][0].get<double>(), w_exact, 1e-13);
  // The identified frequency carries IDA's phase drift over the record.
  EXPECT_LT(std::abs(j["stages"]["identify"]["bases"][0]["difference"].get<double>()), 1e-9);
  EXPECT_NE(j["stages"]["validate"]["integrator"].get<std::string>().find("IDA"), std::string::npos);
  EXPECT_LT(j["stages"]["validate"]["max_error"].get<double>(), 1e-8);
}

// A relaxation oscillation (eps = 3, N = 120): more harmonics than the
// identification models as lines (32) or labels (40); the one-base seed
// takes all of them from one exact period of the settled orbit (its return
// to the section, 4096 samples; rmhb/METHOD.md s.20), and Newton needs one
// or two steps.
TEST(Analyze, RelaxationOscillationSeedsEveryHarmonic) {
  const auto j = Json("analyze vanderpol --set eps=3 --json");
  ASSERT_EQ(j["status"], "converged") << j.dump(1);
  EXPECT_GE(j["stages"]["seed"]["period_harmonics"].get<int>(), 100);
  EXPECT_EQ(j["stages"]["seed"]["fitted_harmonics"].get<int>(), 0);
  EXPECT_LE(j["stages"]["solve"]["iterations"].get<int>(), 3);
  EXPECT_LT(std::abs(j["stages"]["identify"]["bases"][0]["difference"].get<double>()), 1e-9);  // measured 5e-13
  EXPECT_LT(j["stages"]["validate"]["max_error"].get<double>(), 1e-7);  // measured 1.6e-9
}

TEST(Analyze, TextReportNamesEveryStage) {
  const rmhb::testing::CliRun run = Cli("analyze pendulum");
  ASSERT_EQ(run.code, 0) << run.out;
  for (const char* stage : {"trajectory", "identify", "seed", "solve", "validate", "total", "difference"})
    EXPECT_NE(run.out.find(stage), std::string::npos) << stage << "\n" << run.out;
}

// A forced model's record waits until the motion has settled (the
// stroboscopic state, no --transient needed); a --transient given too short
// for Duffing's damping 0.1 leaves a record that is not yet stationary: the
// identification says so, exit 3.
TEST(Analyze, NonStationaryRecordIsReportedNotSolved) {
  const auto settled = Json("analyze duffing --order 18 --json");
  EXPECT_EQ(settled["status"], "converged");
  EXPECT_GT(settled["stages"]["trajectory"]["settle_periods"].get<int>(), 20);
  EXPECT_EQ(settled["stages"]["identify"]["bases"][0]["known"], true);
  const rmhb::testing::CliRun run = Cli("analyze duffing --transient 20 --json");
  EXPECT_EQ(run.code, 3) << run.out;
  const auto j = nlohmann::json::parse(run.out.substr(0, run.out.rfind('}') + 1));
  EXPECT_EQ(j["status"], "identification_failed");
  EXPECT_NE(j["message"].get<std::string>().find("--transient"), std::string::npos);
  EXPECT_FALSE(j["stages"].contains("solve"));
  EXPECT_FALSE(j.contains("frequencies"));
}

TEST(Analyze, BadInputGivesAClearMessageAndExitCode) {
  auto r = Cli("analyze pendulim");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("unknown example 'pendulim'"), std::string::npos) << r.out;
  r = Cli("analyze pendulum --t-end 100 --transient 200");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--transient must be shorter than --t-end"), std::string::npos) << r.out;
  r = Cli("analyze pendulum --frequencies 1,2");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("base frequencies"), std::string::npos) << r.out;
  r = Cli("analyze pendulum --t-end 1e300");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--t-end"), std::string::npos) << r.out;
  r = Cli("analyze pendulum --t-end -5");
  EXPECT_EQ(r.code, 1);
  r = Cli("analyze pendulum --transient nan");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("finite"), std::string::npos) << r.out;
  r = Cli("analyze pendulum --window 9");
  EXPECT_EQ(r.code, 1);
  r = Cli("analyze");
  EXPECT_EQ(r.code, 1);
  r = Cli("analyze --help");
  EXPECT_EQ(r.code, 0);
  for (const char* option : {"--t-end", "--transient", "--window", "--validate-periods", "--frequencies", "--order", "--json"})
    EXPECT_NE(r.out.find(option), std::string::npos) << option;
}

}  // namespace

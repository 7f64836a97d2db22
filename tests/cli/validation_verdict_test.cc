// "validation ok" only when the measured error meets the tolerance: a
// truncated solution, or the quasi-periodic model file solved on the plain
// diamond, is told apart from an accurate one in the text, the JSON and the
// exit code (6).

#include <gtest/gtest.h>

#include "rmhb/cli/exit_codes.h"
#include "tests/cli/cli_run.h"

namespace rmhb::testing {
namespace {

using cli::kExitOk;
using cli::kExitValidationExceeded;

TEST(ValidationVerdict, ATruncatedSolutionExceedsTheTolerance) {
  const CliRun run = Cli("solve duffing --order 3 --validate");
  EXPECT_EQ(run.code, kExitValidationExceeded) << run.out;
  EXPECT_NE(run.out.find("validation   EXCEEDS: max error"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("> tolerance 1e-08"), std::string::npos) << run.out;
  const CliRun json = Capture(std::string(RMHB_CLI) + " solve duffing --order 3 --validate --json");
  EXPECT_EQ(json.code, kExitValidationExceeded);
  const nlohmann::json j = nlohmann::json::parse(json.out);
  EXPECT_EQ(j["validation"]["status"], "exceeds");
  EXPECT_GT(j["validation"]["relative_error"].get<double>(), 1e-3);  // an N = 3 truncation
  EXPECT_EQ(j["validation"]["tolerance"].get<double>(), 1e-8);
  // The same solution against a tolerance it meets.
  EXPECT_EQ(Cli("solve duffing --order 3 --validate --validate-tol 0.1").code, kExitOk);
}

TEST(ValidationVerdict, AnAccurateSolutionIsOkWithItsNumbers) {
  const nlohmann::json j = Json("solve pendulum --order 25 --validate --json");
  EXPECT_EQ(j["validation"]["status"], "ok");
  EXPECT_LT(j["validation"]["relative_error"].get<double>(), 1e-8);
}

TEST(ValidationVerdict, TheAsymmetricPendulumFileOnThePlainDiamondIsNotCalledOk) {
  // The plain diamond at p = 7 (the default before the adaptive index set).
  const CliRun run = Cli("solve examples/models/asym-pendulum.yaml --p 7 --validate --validate-periods 20");
  EXPECT_EQ(run.code, kExitValidationExceeded) << run.out;
  EXPECT_NE(run.out.find("EXCEEDS"), std::string::npos) << run.out;
}

TEST(ValidationVerdict, AnalyzeJudgesItsValidationToo) {
  const CliRun run = Cli("analyze duffing --order 8 --transient 400");
  EXPECT_EQ(run.code, kExitValidationExceeded) << run.out;
  EXPECT_NE(run.out.find("EXCEEDS"), std::string::npos) << run.out;
  const nlohmann::json j = Json("analyze duffing --order 18 --transient 400 --json");
  EXPECT_EQ(j["stages"]["validate"]["status"], "ok");
  EXPECT_LT(j["stages"]["validate"]["relative_error"].get<double>(), 1e-8);
}

}  // namespace
}  // namespace rmhb::testing

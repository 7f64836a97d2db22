// A model with an algebraic equation (a DAE) validates with IDA in every
// command that validates, continuation and the convergence table included.

#include <gtest/gtest.h>

#include "tests/cli/cli_run.h"

namespace rmhb::testing {
namespace {

const char* kDae = "examples/models/softening-dae.yaml";

TEST(DaeValidation, ContinuationValidatesEveryPointWithIda) {
  const nlohmann::json j = Json(std::string("solve ") + kDae + " --order 40 --continue A=1:1.5 --validate --json");
  ASSERT_GT(j["branch"].size(), 2u);
  for (const auto& p : j["branch"]) {
    ASSERT_FALSE(p["validation_error"].is_null()) << p;
    EXPECT_LT(p["validation_error"].get<double>(), 1e-7) << p;  // N = 40 truncation at A = 1.5
  }
}

TEST(DaeValidation, ConvergenceTableMeasuresAgainstIda) {
  const CliRun run = Cli(std::string("convergence ") + kDae + " --methods rhb --orders 10,30");
  EXPECT_EQ(run.code, 0) << run.out;
  EXPECT_NE(run.out.find("against IDA"), std::string::npos) << run.out;
}

}  // namespace
}  // namespace rmhb::testing

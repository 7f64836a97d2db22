// `rmhb solve --tol`: automatic order selection and the condition estimate
// as a script sees them (exit codes, JSON fields, messages).

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/cli_run.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace {

using rmhb::testing::Capture;
using rmhb::testing::CliRun;

CliRun Rmhb(const std::string& args, bool with_stderr = true) {
  return Capture(std::string(RMHB_CLI) + " " + args + (with_stderr ? " 2>&1" : " 2>/dev/null"));
}

TEST(CliTol, ChoosesTheOrderAndReportsTheEstimate) {
  const CliRun run = Rmhb("solve relativistic --set beta=0.95 --order 25 --tol 1e-10 --json", false);
  ASSERT_EQ(run.code, 0) << run.out;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["status"], "converged");
  const auto& selection = j["order_selection"];
  EXPECT_EQ(selection["tolerance"], 1e-10);
  // The first solve at half the start order (METHOD.md s.8).
  EXPECT_EQ(selection["orders"][0], 12);
  EXPECT_EQ(selection["orders"].back(), j["order"]);
  EXPECT_LE(selection["estimate"].get<double>(), 1e-10);
  EXPECT_LE(std::abs(j["reference"]["amplitude_error"].get<double>()), 1e-10);
  EXPECT_LE(std::abs(j["reference"]["frequency_error"].get<double>()), 1e-10);
  EXPECT_GT(j["reciprocal_condition"].get<double>(), 0);
  EXPECT_LT(j["reciprocal_condition"].get<double>(), 1);
}

TEST(CliTol, ReciprocalConditionIsReportedByTheRegularisedSolversToo) {
  const CliRun run = Rmhb("solve duffing --order 10 --solver lm --json", false);
  ASSERT_EQ(run.code, 0) << run.out;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_GT(j["reciprocal_condition"].get<double>(), 0);
  EXPECT_LT(j["reciprocal_condition"].get<double>(), 1);
}

TEST(CliTol, TextReportNamesTheChosenOrder) {
  const CliRun run = Rmhb("solve pendulum --set theta0=3 --tol 1e-10");
  ASSERT_EQ(run.code, 0) << run.out;
  EXPECT_NE(run.out.find("chosen for target 1e-10 on the state"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("estimated error: state"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("1/cond(J)"), std::string::npos) << run.out;
}

TEST(CliTol, TheTargetIsTheDefaultUnlessTheOrderIsFixed) {
  const auto fixed = nlohmann::json::parse(Rmhb("solve duffing --order 20 --json", false).out);
  EXPECT_FALSE(fixed.contains("order_selection"));
  const auto chosen = nlohmann::json::parse(Rmhb("solve duffing --json", false).out);
  EXPECT_EQ(chosen["order_selection"]["tolerance"], 1e-10);
  EXPECT_EQ(chosen["order_selection"]["quantity"], "state");
  EXPECT_TRUE(chosen["order_selection"]["calibrated"].get<bool>());
  EXPECT_LE(chosen["order_selection"]["state_estimate"].get<double>(), 1e-10);
}

TEST(CliTol, NegativeOrNanToleranceIsBadInput) {
  for (const char* tol : {"-1e-10", "nan", "inf", "abc"}) {
    const CliRun run = Rmhb(std::string("solve pendulum --tol ") + tol);
    EXPECT_TRUE(run.code == 2 || (std::string(tol) == "abc" && run.code == 1)) << tol << ": " << run.code;
    EXPECT_NE(run.out.find("--tol"), std::string::npos) << run.out;
  }
}

}  // namespace

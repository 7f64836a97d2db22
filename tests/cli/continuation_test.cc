// `rmhb solve --continue` as a script sees it: the branch in JSON and CSV,
// folds, references, exit codes.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/cli_run.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

namespace {

using rmhb::testing::Capture;
using rmhb::testing::Cli;
using rmhb::testing::CliRun;


nlohmann::json Json(const std::string& args, int expected_code = 0) {
  const CliRun r = Capture(std::string(RMHB_CLI) + " " + args);
  EXPECT_EQ(r.code, expected_code) << args;
  return nlohmann::json::parse(r.out);
}

TEST(CliContinuation, DuffingFrequencyResponseThroughBothFolds) {
  const auto j = Json("solve duffing --set F=0.5 --order 15 --continue w=0.5:3 --json");
  EXPECT_EQ(j["status"], "completed");
  EXPECT_EQ(j["method"], "pseudo-arclength");
  EXPECT_EQ(j["parameter"], "w");
  ASSERT_EQ(j["folds"].size(), 2u);
  // The library test finds the same folds by an independent solve.
  EXPECT_NEAR(j["folds"][0].get<double>(), 2.2119353170197, 1e-11);
  EXPECT_NEAR(j["folds"][1].get<double>(), 1.4386701455143, 1e-11);
  const auto& branch = j["branch"];
  ASSERT_EQ(branch.size(), j["points"].get<size_t>());
  EXPECT_EQ(branch.front()["parameter"], 0.5);
  EXPECT_EQ(branch.back()["parameter"], 3.0);
  int marked = 0, folds_passed = 0;
  for (const auto& p : branch) {
    // Hill's method: the middle branch, between the folds, is the unstable one.
    if (p["fold"].get<bool>()) ++folds_passed;
    else EXPECT_EQ(p["stability"], folds_passed == 1 ? "unstable" : "stable") << p["parameter"];
    for (const char* key : {"parameter", "frequencies", "amplitude", "residual", "fold", "stability"})
      EXPECT_TRUE(p.contains(key)) << key;
    EXPECT_LT(p["residual"].get<double>(), 1e-12);
    // A known forcing frequency is the parameter itself.
    EXPECT_EQ(p["frequencies"][0], p["parameter"]);
    marked += p["fold"].get<bool>();
  }
  EXPECT_EQ(marked, 2);
}

TEST(CliContinuation, RelativisticSweepAgainstTheExactReference) {
  const std::string csv = ::testing::TempDir() + "relativistic_branch.csv";
  const auto j = Json("solve relativistic --order 60 --natural --continue beta=0.5:0.9 --json --csv " + csv);
  EXPECT_EQ(j["status"], "completed");
  EXPECT_EQ(j["method"], "natural");
  for (const auto& p : j["branch"]) {
    EXPECT_LT(std::abs(p["reference"]["amplitude_error"].get<double>()), 1e-10) << p["parameter"];
    EXPECT_LT(std::abs(p["reference"]["frequency_error"].get<double>()), 1e-10) << p["parameter"];
  }
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line,
            "beta,w1,amplitude,residual,fold,stability,frequency_error,amplitude_error,stability_method,"
            "max_multiplier,bifurcation,branch");
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, static_cast<int>(j["branch"].size()));
}

TEST(CliContinuation, TextOutputMarksFolds) {
  const CliRun r = Cli("solve duffing --set F=0.5 --order 12 --continue w=1:2.5 --steps 10");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("pseudo-arclength continuation in w from 1 to 2.5: completed"), std::string::npos) << r.out;
  size_t folds = 0;
  for (size_t at = r.out.find("<- fold"); at != std::string::npos; at = r.out.find("<- fold", at + 1)) ++folds;
  EXPECT_EQ(folds, 2u) << r.out;
}

TEST(CliContinuation, ModelFileBranchThatTurnsBackOutOfTheRange) {
  // The automatic recast of examples/models/duffing.yaml: from w = 1.8 up the
  // resonant branch, over the upper fold and back down the middle branch,
  // which leaves the range through its start (exit 0, status left_range).
  const auto j = Json("solve examples/models/duffing.yaml --set F=0.5 --order 10 --continue w=1.8:2.5 "
                      "--steps 5 --no-stability --json");
  EXPECT_EQ(j["status"], "left_range");
  EXPECT_NE(j["message"].get<std::string>().find("left the range through w = 1.8"), std::string::npos);
  ASSERT_EQ(j["folds"].size(), 1u);
  EXPECT_NEAR(j["folds"][0].get<double>(), 2.2119353170197, 1e-11);  // N = 10: 7e-13 off N = 30
  EXPECT_LT(j["branch"].back()["parameter"].get<double>(), 1.8);
}

TEST(CliContinuation, StabilityCanBeSkipped) {
  const auto j = Json("solve duffing --set F=0.5 --order 10 --continue w=1:1.2 --no-stability --json");
  EXPECT_EQ(j["status"], "completed");
  for (const auto& p : j["branch"]) EXPECT_EQ(p["stability"], "unknown");
}

TEST(CliContinuation, NaturalContinuationStopsAtAFoldWithExitCode3) {
  const CliRun r = Cli("solve duffing --set F=0.5 --order 12 --natural --continue w=1.5:3");
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("turning point"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("max|F|"), std::string::npos) << r.out;
}

TEST(CliContinuation, BadInputExitsWith2) {
  CliRun r = Cli("solve duffing --continue q=1:2");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("no parameter 'q'"), std::string::npos) << r.out;
  r = Cli("solve duffing --continue w=1:1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("range is empty"), std::string::npos) << r.out;
  for (const char* range : {"w=1", "w=1:2:3", "w=1,2", "=1:2", "w"}) {
    r = Cli(std::string("solve duffing --continue ") + range);
    EXPECT_EQ(r.code, 2) << range;
    EXPECT_NE(r.out.find("NAME=a:b"), std::string::npos) << r.out;
  }
  r = Cli("solve duffing --continue w=1:abc");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("'abc' is not a finite number"), std::string::npos) << r.out;
  r = Cli("solve relativistic --continue beta=0.5:1.5");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("end of the range"), std::string::npos) << r.out;
  r = Cli("solve relativistic --continue beta=1.5:0.5");
  EXPECT_EQ(r.code, 2);
  r = Cli("solve duffing --continue w=1:2 --eval 0:0.1:1 --csv /dev/null");
  EXPECT_EQ(r.code, 2);
  r = Cli("solve duffing --continue w=1:2 --steps 0");
  EXPECT_EQ(r.code, 1);
}

}  // namespace

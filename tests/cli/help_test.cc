// Every command documents its options and its exit codes.

#include <gtest/gtest.h>

#include <string>

#include "tests/cli/cli_run.h"

namespace {

using rmhb::testing::Cli;

TEST(Help, EveryCommandHasOptionsAndExitCodes) {
  for (const std::string cmd : {"", "solve", "recast", "identify", "list", "simulate", "convergence"}) {
    const auto r = Cli(cmd + " --help");
    EXPECT_EQ(r.code, 0) << cmd;
    EXPECT_NE(r.out.find("Exit codes"), std::string::npos) << cmd << "\n" << r.out;
    EXPECT_NE(r.out.find("--help"), std::string::npos) << cmd;
  }
  const auto convergence = Cli("convergence --help").out;
  for (const char* option : {"--orders", "--methods", "--solver", "--conditions", "--taylor", "--plot", "--json"})
    EXPECT_NE(convergence.find(option), std::string::npos) << option;
  const auto simulate = Cli("simulate --help").out;
  for (const char* option : {"--t-end", "--dt", "--csv", "--rtol", "--plot", "--json", "default"})
    EXPECT_NE(simulate.find(option), std::string::npos) << option;
}

}  // namespace

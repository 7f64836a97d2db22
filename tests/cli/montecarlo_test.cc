// `rmhb montecarlo` as a script sees it: the Table-1 census in JSON, the same
// census for a seed whatever the thread count, and exit code 2 on bad input.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/cli_run.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

using rmhb::testing::Capture;
using rmhb::testing::CliRun;

CliRun RunCli(const std::string& args) { return Capture(std::string(RMHB_CLI) + " " + args); }

const char* kDuffing = "montecarlo duffing --set w=2 --order 3 --seed 5 ";

TEST(MonteCarloCli, RhbThreePhysicalHdhbAliasedStabilityAgrees) {
  const CliRun r = RunCli(std::string(kDuffing) + "--starts 150 --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["methods"].size(), 2u);
  const auto& rhb = j["methods"][0];
  const auto& hdhb = j["methods"][1];
  EXPECT_EQ(rhb["method"], "rhb");
  EXPECT_TRUE(rhb["alias_free"].get<bool>());
  EXPECT_FALSE(hdhb["alias_free"].get<bool>());
  EXPECT_EQ(rhb["distinct_solutions"], 3);
  EXPECT_EQ(rhb["non_physical_solutions"], 0);
  EXPECT_EQ(rhb["shares"]["non_physical"].get<double>(), 0.0);
  EXPECT_GT(hdhb["non_physical_solutions"].get<int>(), 0);
  int unstable = 0;
  for (const auto& c : rhb["clusters"]) {
    unstable += c["class"] == "physical-unstable";
    // Hill's method and the CVODE monodromy matrix give the same verdict,
    // and the reference solution closes on itself under integration.
    EXPECT_TRUE(c["stability"]["agree"].get<bool>()) << c.dump();
    EXPECT_LT(c["stability"]["floquet"]["closure_error"].get<double>(), 1e-9);
    EXPECT_EQ(c["solution"]["coefficients"]["x"]["cos"].size(), 4u);
  }
  EXPECT_EQ(unstable, 1);
}

TEST(MonteCarloCli, SameSeedSameResultOnOneOrTwoThreads) {
  auto census = [](const std::string& threads) {
    const CliRun r = RunCli(std::string(kDuffing) + "--starts 30 --no-floquet --json --threads " + threads);
    EXPECT_EQ(r.code, 0) << r.out;
    auto j = nlohmann::json::parse(r.out);
    for (auto& m : j["methods"]) m.erase("solve_cpu_seconds");
    return j["methods"];
  };
  EXPECT_EQ(census("1"), census("2"));
}

TEST(MonteCarloCli, BadInputIsExitTwoWithAMessage) {
  for (const std::string args :
       {"--starts 0", "--starts -3", "--range=2:-2", "--range 1", "--range a:b", "--threads -1",
        "--methods rhb,xyz"}) {
    const CliRun r = RunCli(std::string(kDuffing) + args + " 2>&1");
    EXPECT_EQ(r.code, 2) << args << ": " << r.out;
    EXPECT_NE(r.out.find("error"), std::string::npos) << args << ": " << r.out;
  }
  EXPECT_EQ(RunCli("montecarlo no-such-model --starts 5 2>&1").code, 2);
  EXPECT_EQ(RunCli("montecarlo pendulum --starts 5 2>&1").code, 2);  // Hill cannot classify it
  EXPECT_EQ(RunCli("montecarlo vanderpol --starts 5 2>&1").code, 2);  // autonomous
  EXPECT_EQ(RunCli("montecarlo 2>&1").code, 1);                       // usage
}

// rmhb runs montecarlo and sweep by becoming rmhb-parallel (MPI, HDF5) from
// its own directory; every other command runs without those libraries.
TEST(MonteCarloCli, OnlyTheParallelBinaryLoadsMpiAndHdf5) {
  const std::string dir = ::testing::TempDir() + "rmhb_light_" + std::to_string(::getpid());
  ASSERT_EQ(std::system(("mkdir -p " + dir + " && cp " + RMHB_CLI + " " + dir + "/rmhb").c_str()), 0);
  const std::string light = dir + "/rmhb";
  // The dynamic loader's list of what the binary loads (what ldd prints).
  const CliRun loaded = Capture("LD_TRACE_LOADED_OBJECTS=1 " + light);
  EXPECT_EQ(loaded.out.find("libmpi"), std::string::npos) << loaded.out;
  EXPECT_EQ(loaded.out.find("hdf5"), std::string::npos) << loaded.out;
  EXPECT_NE(loaded.out.find("libginac"), std::string::npos) << loaded.out;
  const CliRun parallel = Capture(std::string("LD_TRACE_LOADED_OBJECTS=1 ") + RMHB_CLI + "-parallel");
  EXPECT_NE(parallel.out.find("libmpi"), std::string::npos) << parallel.out;
  EXPECT_NE(parallel.out.find("hdf5"), std::string::npos) << parallel.out;
  // Without rmhb-parallel beside it: solve works, montecarlo says what is missing.
  EXPECT_EQ(Capture(light + " solve duffing --order 3 > /dev/null 2>&1").code, 0);
  const CliRun missing = Capture(light + " montecarlo duffing --starts 5 2>&1");
  EXPECT_EQ(missing.code, 4) << missing.out;
  EXPECT_NE(missing.out.find("rmhb-parallel"), std::string::npos) << missing.out;
  std::system(("rm -rf " + dir).c_str());
}

}  // namespace

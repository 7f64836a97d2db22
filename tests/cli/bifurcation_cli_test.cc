// `solve --continue` with its bifurcations as a user sees them: every point's
// stability and its method, the located period doublings and Neimark-Sacker
// point in the text, the JSON, the CSV and the plot, and --switch-branches'
// period-2T branch and torus. Model files written for the tests
// (tests/pipeline/models), defaults only; the numbers themselves are checked
// against brute-force CVODE references in tests/pipeline/branch_test.cc.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/cli/cli_run.h"

namespace rmhb::testing {
namespace {

namespace fs = std::filesystem;

const std::string kQuadratic = "tests/pipeline/models/quadratic-duffing.yaml";
const std::string kSelfExcited = "tests/pipeline/models/forced-self-excited.yaml";

std::string Temp(const std::string& name) {
  return (fs::temp_directory_path() / ("rmhb-bif-" + std::to_string(::getpid()) + "-" + name)).string();
}

std::string Read(const std::string& file) {
  std::ifstream in(file);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

size_t Count(const std::string& text, const std::string& word) {
  size_t n = 0;
  for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++n;
  return n;
}

TEST(CliBifurcations, PeriodDoublingsAndTheirPeriodTwoBranchInJsonCsvAndPlot) {
  const std::string csv = Temp("pd.csv"), svg = Temp("pd.svg");
  const auto j = Json("solve " + kQuadratic + " --order 12 --continue w=2.5:1.5 --max-step 0.2 --switch-branches "
                      "--json --csv " + csv + " --plot " + svg);
  ASSERT_EQ(j["status"], "completed");
  ASSERT_EQ(j["bifurcations"].size(), 2u) << j["bifurcations"].dump();
  for (const auto& b : j["bifurcations"]) {
    EXPECT_EQ(b["type"], "period_doubling");
    EXPECT_TRUE(b["located"].get<bool>());
    EXPECT_NEAR(b["multiplier"][0].get<double>(), -1, 1e-8);
    EXPECT_LE(std::abs(b["distance"].get<double>()), b["tolerance"].get<double>());
    EXPECT_EQ(j["branch"][b["point"].get<int>()]["bifurcation"], "period_doubling");
  }
  for (const auto& p : j["branch"]) {
    EXPECT_NE(p["stability"], "unknown");
    EXPECT_NE(p["stability_method"], "none");
    EXPECT_GT(p["multipliers"].size(), 0u);
  }
  // The period-2T branch from the first doubling merges back at the second,
  // which is then not traced again.
  const auto& doubled = j["doubled_branches"];
  ASSERT_EQ(doubled.size(), 2u);
  EXPECT_TRUE(doubled[0]["started"].get<bool>());
  EXPECT_EQ(doubled[0]["status"], "stopped");
  EXPECT_EQ(doubled[0]["order"], 24);
  EXPECT_GT(doubled[0]["branch"].size(), 5u);
  EXPECT_NE(doubled[1]["message"].get<std::string>().find("ends here"), std::string::npos) << doubled[1].dump();
  for (const auto& p : doubled[0]["branch"]) EXPECT_NEAR(p["frequencies"][0].get<double>(), p["parameter"].get<double>() / 2, 1e-14);

  const std::string table = Read(csv);
  EXPECT_EQ(Count(table, ",period_doubling,0\n"), 2u);
  EXPECT_EQ(Count(table, ",1\n"), doubled[0]["branch"].size());
  EXPECT_NE(table.find(",stability_method,max_multiplier,bifurcation,branch\n"), std::string::npos);
  const std::string data = Read(j["plot_data"]);
  EXPECT_EQ(Count(data, " PD 0\n"), 2u);
  EXPECT_EQ(Count(data, " 1\n"), doubled[0]["branch"].size());
  const std::string picture = Read(svg);
  EXPECT_EQ(Count(picture, "PD w = "), 2u);
  EXPECT_NE(picture.find("period 2T"), std::string::npos);
  for (const std::string& f : {csv, svg, svg + ".dat"}) fs::remove(f);
}

TEST(CliBifurcations, TheTextSaysWhereAndHowWellEachPointWasLocated) {
  const CliRun r = Cli("solve " + kQuadratic + " --order 12 --continue w=2.5:1.5 --max-step 0.2");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(Count(r.out, "period doubling at w = "), 2u) << r.out;
  EXPECT_EQ(Count(r.out, "<- PD"), 2u) << r.out;
  EXPECT_EQ(Count(r.out, "located: |mu + 1| = "), 2u) << r.out;
  // Every applicable method at the first point, and how well they agree.
  EXPECT_NE(r.out.find("stability cross-check: hb-monodromy"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(hb-monodromy-Hill)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(Hill-monodromy)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("max|mu|"), std::string::npos) << r.out;
}

TEST(CliBifurcations, TheTorusPastTheNeimarkSackerPointIsSolvedAndValidated) {
  const auto j = Json("solve " + kSelfExcited + " --order 12 --continue w=1.1:1.2 --max-step 0.2 --switch-branches --json");
  ASSERT_EQ(j["bifurcations"].size(), 1u) << j["bifurcations"].dump();
  const auto& ns = j["bifurcations"][0];
  EXPECT_EQ(ns["type"], "neimark_sacker");
  EXPECT_GT(ns["torus_frequency"].get<double>(), 0);
  ASSERT_EQ(j["tori"].size(), 1u);
  const auto& t = j["tori"][0];
  ASSERT_TRUE(t["solved"].get<bool>()) << t.dump();
  EXPECT_EQ(t["frequencies"].size(), 2u);
  EXPECT_EQ(t["periodic_side"], "unstable");
  EXPECT_EQ(t["validation"]["status"], "ok") << t["validation"].dump();
  EXPECT_LT(t["validation"]["relative_error"].get<double>(), 1e-8);
  EXPECT_EQ(t["solution"]["frequencies"].size(), 2u);
}

TEST(CliBifurcations, PinnedAuxiliariesGetTheirStabilityAtEveryPoint) {
  const auto j = Json("solve tests/pipeline/models/forced-pendulum.yaml --order 30 --set W=1 --continue W=1:1.1 --json");
  ASSERT_EQ(j["status"], "completed");
  EXPECT_EQ(j["stability_note"], "");
  for (const auto& p : j["branch"]) EXPECT_EQ(p["stability_method"], "monodromy");
}

TEST(CliBifurcations, OptionsThatNeedContinuationOrStability) {
  const std::string model = kQuadratic + " --order 8";
  for (const char* bad : {"--switch-branches", "--stability-method hill"}) {
    const CliRun r = Cli("solve " + model + " " + std::string(bad));
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_NE(r.out.find("needs --continue"), std::string::npos) << r.out;
  }
  const CliRun off = Cli("solve " + model + " --continue w=2:2.1 --no-stability --switch-branches");
  EXPECT_EQ(off.code, 2);
  EXPECT_NE(off.out.find("needs the stability that --no-stability turns off"), std::string::npos) << off.out;
  const CliRun natural = Cli("solve " + model + " --continue w=2:2.1 --natural --switch-branches");
  EXPECT_EQ(natural.code, 2);
  const CliRun method = Cli("solve " + model + " --continue w=2:2.1 --stability-method qz");
  EXPECT_EQ(method.code, 1);
}

}  // namespace
}  // namespace rmhb::testing

// The command line as a script sees it: exit codes, JSON fields, messages.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "tests/cli/cli_run.h"

namespace {

using rmhb::testing::Cli;
using rmhb::testing::CliRun;
using rmhb::testing::Json;

TEST(Cli, SolveJsonHasTheDocumentedFields) {
  const auto j = Json("solve pendulum --set theta0=1.5 --order 25 --json --validate");
  EXPECT_EQ(j["status"], "converged");
  for (const char* key : {"frequencies", "order", "samples", "iterations", "residual", "seconds",
                          "coefficients", "auxiliary_coefficients", "validation", "reference"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["order"], 25);
  EXPECT_EQ(j["coefficients"]["theta"]["cos"].size(), 26u);
  EXPECT_EQ(j["coefficients"]["theta"]["sin"][0], 0.0);
  EXPECT_TRUE(j["auxiliary_coefficients"].contains("s"));
  EXPECT_FALSE(j["coefficients"].contains("s"));
  EXPECT_NEAR(j["frequencies"][0].get<double>(), 0.860608346679612985103549304862, 1e-13);
  EXPECT_NEAR(j["coefficients"]["theta"]["cos"][1].get<double>(), 1.52004746521332765948913464242, 1e-13);
  EXPECT_LT(j["validation"]["max_error"].get<double>(), 1e-9);  // CVODE's own accuracy
  EXPECT_LT(std::abs(j["reference"]["frequency_error"].get<double>()), 1e-13);
}

TEST(Cli, MethodsAndSolversAreSelectable) {
  const auto hdhb = Json("solve duffing --order 5 --method hdhb --json");
  EXPECT_EQ(hdhb["samples"], 11);
  EXPECT_EQ(hdhb["alias_free"], false);
  const auto aft = Json("solve duffing --order 5 --method aft --json");
  EXPECT_EQ(aft["samples"], 32);
  const auto lm = Json("solve relativistic --order 20 --solver lm --json");
  EXPECT_EQ(lm["status"], "converged");
  EXPECT_EQ(lm["solver"], "lm");
}

TEST(Cli, BadInputGivesAClearMessageAndExitCode) {
  CliRun r = Cli("solve pendulim");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("unknown example 'pendulim'"), std::string::npos) << r.out;
  r = Cli("solve pendulum --set theta=1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("no parameter 'theta'"), std::string::npos) << r.out;
  r = Cli("solve pendulum --set theta0=abc");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("not a number"), std::string::npos) << r.out;
  r = Cli("solve pendulum --set theta0=nan");
  EXPECT_EQ(r.code, 2);
  r = Cli("solve pendulum --order 0");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("order"), std::string::npos) << r.out;
  r = Cli("solve duffing --order 5 --samples 12");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("alias"), std::string::npos) << r.out;
  r = Cli("solve pendulum --method magic");
  EXPECT_EQ(r.code, 1);
  r = Cli("frobnicate");
  EXPECT_EQ(r.code, 1);
  r = Cli("");
  EXPECT_EQ(r.code, 1);
}

TEST(Cli, NonConvergenceIsReportedWithTheResidual) {
  // Far too few iterations to converge from the starting guess.
  CliRun r = Cli("solve vanderpol --set eps=1 --order 10 --max-iterations 1");
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("not converged"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("max|F|"), std::string::npos) << r.out;
  const auto j = Json("solve vanderpol --set eps=1 --order 10 --max-iterations 1 --json");
  EXPECT_NE(j["status"], "converged");
  EXPECT_FALSE(j.contains("coefficients"));
  EXPECT_TRUE(j["residual"].is_number());
}

TEST(Cli, ModelFilesWorkWhereExamplesDo) {
  const auto j = Json("solve examples/models/pendulum.yaml --order 25 --json");
  EXPECT_EQ(j["status"], "converged");
  EXPECT_NEAR(j["frequencies"][0].get<double>(), 0.860608346679612985103549304862, 1e-13);
  EXPECT_EQ(j["harmonics"].size(), 26u);
  const auto r = Json("recast examples/models/relativistic.yaml --json");
  EXPECT_EQ(r["degree"], 4);
  EXPECT_EQ(r["equations"].size(), 3u);
  CliRun text = Cli("recast examples/models/pendulum.yaml");
  EXPECT_EQ(text.code, 0);
  EXPECT_NE(text.out.find("sin(theta)"), std::string::npos) << text.out;
}

TEST(Cli, ModelErrorsSayWhere) {
  const std::string path = testing::TempDir() + "/bad_model.yaml";
  FILE* f = fopen(path.c_str(), "w");
  fputs("name: bad\nvariables: [x]\nequations:\n  - \"x'' + sin(thta) = 0\"\nfrequencies: [{guess: 1}]\n", f);
  fclose(f);
  const CliRun r = Cli("solve " + path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("bad_model.yaml:4:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("thta"), std::string::npos) << r.out;
  EXPECT_EQ(Cli("solve /nonexistent/model.yaml").code, 2);
}

TEST(Cli, EvalWritesTheTimeSeries) {
  const std::string csv = testing::TempDir() + "/pendulum_series.csv";
  const auto j = Json("solve pendulum --eval 0:0.5:10 --csv " + csv + " --json");
  EXPECT_EQ(j["eval"]["points"], 21);
  FILE* f = fopen(csv.c_str(), "r");
  ASSERT_NE(f, nullptr);
  char header[256];
  ASSERT_NE(fgets(header, sizeof header, f), nullptr);
  EXPECT_EQ(std::string(header), "t,theta,v,s,c\n");
  double t, theta;
  ASSERT_EQ(fscanf(f, "%lf,%lf", &t, &theta), 2);
  EXPECT_EQ(t, 0.0);
  EXPECT_NEAR(theta, 1.5, 1e-13);
  fclose(f);
  EXPECT_EQ(Cli("solve pendulum --eval 0:-1:10 --csv " + csv).code, 2);
  EXPECT_EQ(Cli("solve pendulum --eval 0:1:10").code, 2);
}

TEST(Cli, IdentifyFindsTheBasesOfAUserSignal) {
  // Two incommensurate bases and a combination tone stronger than w2.
  const double w1 = 1.0, w2 = 0.5 * (1 + std::sqrt(5.0));
  const std::string path = testing::TempDir() + "/quasi_periodic_signal.csv";
  FILE* f = fopen(path.c_str(), "w");
  fputs("t,x\n", f);
  for (int i = 0; i < 40000; ++i) {
    const double t = 0.1 * i;
    fprintf(f, "%.17g,%.17g\n", t,
            std::cos(w1 * t) + 0.01 * std::sin(w2 * t) + 0.2 * std::cos((2 * w1 - w2) * t + 0.3));
  }
  fclose(f);
  const auto j = Json("identify --signal " + path + " --json");
  EXPECT_EQ(j["status"], "success") << j.dump(1);
  ASSERT_EQ(j["bases"].size(), 2u);
  // Any unimodular basis of the same lattice is right ({w1, 2 w1 - w2} is a
  // natural one here): every line must be found, exactly, with a label that
  // rebuilds its frequency from the bases.
  const double b1 = j["bases"][0]["frequency"], b2 = j["bases"][1]["frequency"];
  std::vector<double> lines;
  for (const auto& c : j["components"]) {
    ASSERT_EQ(c["label"].size(), 2u) << c.dump();
    const double rebuilt = c["label"][0].get<int>() * b1 + c["label"][1].get<int>() * b2;
    EXPECT_NEAR(rebuilt, c["frequency"].get<double>(), 1e-11);
    lines.push_back(c["frequency"]);
  }
  std::sort(lines.begin(), lines.end());
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_NEAR(lines[0], 2 * w1 - w2, 1e-11);
  EXPECT_NEAR(lines[1], w1, 1e-11);
  EXPECT_NEAR(lines[2], w2, 1e-11);
  // A malformed file names the line.
  FILE* g = fopen((path + ".bad").c_str(), "w");
  fputs("t,x\n0,1\n0.1,abc\n", g);
  fclose(g);
  const CliRun bad = Cli("identify --signal " + path + ".bad");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.out.find(":3:"), std::string::npos) << bad.out;
}

TEST(Cli, IdentifyCutsAUserSignalByTransientAndTEnd) {
  // A transient (a decaying tone) the cut removes: then one clean line.
  const double w = 1.3;
  const std::string path = testing::TempDir() + "/transient_signal.csv";
  FILE* f = fopen(path.c_str(), "w");
  fputs("t,x\n", f);
  for (int i = 0; i < 20000; ++i) {
    const double t = 0.1 * i;
    fprintf(f, "%.17g,%.17g\n", t, std::cos(w * t) + (t < 100 ? std::exp(-t) * std::cos(3.7 * t) : 0.0));
  }
  fclose(f);
  const auto j = Json("identify --signal " + path + " --transient 200 --t-end 1800 --json");
  EXPECT_EQ(j["samples"], 16000);  // t in [200, 1800)
  EXPECT_EQ(j["status"], "success") << j.dump(1);
  ASSERT_EQ(j["bases"].size(), 1u);
  EXPECT_NEAR(j["bases"][0]["frequency"].get<double>(), w, 1e-12);
  const CliRun too_short = Cli("identify --signal " + path + " --transient 1999");
  EXPECT_EQ(too_short.code, 2);
  EXPECT_NE(too_short.out.find("64 needed"), std::string::npos) << too_short.out;
}

TEST(Cli, QuasiPeriodicSolveReportsHarmonicPairs) {
  const auto j = Json("solve forced-vanderpol --json");
  ASSERT_EQ(j["status"], "converged") << j.dump(1);
  ASSERT_EQ(j["frequencies"].size(), 2u);
  EXPECT_EQ(j["frequencies"][0], 2.3);  // the forcing, known
  EXPECT_NEAR(j["frequencies"][1].get<double>(), 0.997466254703, 1e-9);
  const auto& h = j["harmonics"];
  ASSERT_GT(h.size(), 10u);
  EXPECT_EQ(h[0], nlohmann::json::array({0, 0}));
  for (const auto& k : h) EXPECT_EQ(k.size(), 2u);
  EXPECT_EQ(j["coefficients"]["x"]["cos"].size(), h.size());
  EXPECT_EQ(j["coefficients"]["x"]["sin"].size(), h.size());
  // The GCD rule is refused, with the sample count it would need.
  const CliRun gcd = Cli("solve asym-pendulum --sampling gcd");
  EXPECT_EQ(gcd.code, 2);
  EXPECT_NE(gcd.out.find("samples"), std::string::npos) << gcd.out;
  EXPECT_EQ(Cli("solve forced-vanderpol --frequencies 2.3").code, 2);  // one of two
  EXPECT_EQ(Cli("solve forced-vanderpol --frequencies 2.3,-1").code, 2);
}

TEST(Cli, HelpAndListWork) {
  CliRun r = Cli("--help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("Exit codes"), std::string::npos);
  r = Cli("solve --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--validate"), std::string::npos);
  const auto list = Json("list --json");
  EXPECT_GE(list.size(), 5u);
}

}  // namespace

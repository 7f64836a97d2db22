// `rmhb convergence`: the error-against-time table, checked against the
// exact pendulum (elliptic integral frequency, nome series solution).

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tests/cli/cli_run.h"

namespace {

using rmhb::testing::Cli;
using rmhb::testing::Json;

const nlohmann::json& Column(const nlohmann::json& table, const std::string& name) {
  for (const auto& c : table["columns"])
    if (c["name"] == name) return c;
  ADD_FAILURE() << "no column " << name;
  static const nlohmann::json none;
  return none;
}

TEST(Convergence, PendulumRhbConvergesAndTaylorStalls) {
  const auto table = Json("convergence pendulum --orders 5:25:10 --json");
  ASSERT_EQ(table["orders"], nlohmann::json({5, 15, 25}));
  for (const char* name : {"rhb", "hdhb", "aft", "taylor", "original"}) {
    const auto& rows = Column(table, name)["rows"];
    ASSERT_EQ(rows.size(), 3u) << name;
    for (const auto& r : rows) {
      EXPECT_EQ(r["status"], "converged") << name << " N=" << r["order"];
      EXPECT_GT(r["seconds"].get<double>(), 0.0);
    }
  }
  // RHB: geometric decrease to round-off, against the exact solution (nome
  // series) and the exact frequency (elliptic integral).
  const auto& rhb = Column(table, "rhb")["rows"];
  EXPECT_GT(rhb[0]["max_error"].get<double>(), rhb[1]["max_error"].get<double>());
  EXPECT_GT(rhb[1]["max_error"].get<double>(), rhb[2]["max_error"].get<double>());
  EXPECT_LT(rhb[2]["max_error"].get<double>(), 1e-10);
  EXPECT_EQ(rhb[2]["error"], rhb[2]["max_error"]);
  EXPECT_EQ(rhb[2]["samples"], 80);  // M > 3 N, FFT-friendly
  EXPECT_EQ(Column(table, "hdhb")["rows"][2]["samples"], 51);
  EXPECT_EQ(Column(table, "aft")["rows"][2]["samples"], 128);
  EXPECT_LT(Column(table, "hdhb")["rows"][2]["max_error"].get<double>(), 1e-10);
  EXPECT_LT(Column(table, "aft")["rows"][2]["max_error"].get<double>(), 1e-10);
  EXPECT_LT(std::abs(rhb[2]["frequency_error"].get<double>()), 1e-14);

  // RHB-Taylor (sin to order 15, phi = 15, M > 16 N): the truncated model
  // stalls near 1.5^17/17! ~ 3e-12 however many harmonics it gets.
  EXPECT_EQ(table["taylor"]["degree"], 15);
  const auto& taylor = Column(table, "taylor")["rows"];
  EXPECT_GE(taylor[2]["samples"].get<int>(), 401);
  EXPECT_GT(taylor[2]["max_error"].get<double>(), 1e-13);
  EXPECT_LT(taylor[2]["max_error"].get<double>(), 1e-10);
  EXPECT_GT(taylor[2]["max_error"].get<double>(), 100 * rhb[2]["max_error"].get<double>());
  EXPECT_NEAR(taylor[1]["max_error"].get<double>(), taylor[2]["max_error"].get<double>(),
              0.5 * taylor[2]["max_error"].get<double>());  // no progress from N = 15 to 25
  // HB-AFT on the original sin(theta): aliases, but at M = 2^k >= 4N + 1 the
  // folded harmonics of an analytic solution are far below the truncation
  // error, so it follows RHB (see notes): its frequency is checked directly.
  const auto& original = Column(table, "original")["rows"];
  EXPECT_LT(original[2]["max_error"].get<double>(), 1e-12);
  EXPECT_GT(original[0]["max_error"].get<double>(), original[2]["max_error"].get<double>());
}

TEST(Convergence, SolversAndConditionSchemesAddColumns) {
  const auto table = Json("convergence pendulum --orders 10 --methods rhb --solver newton,lm "
                          "--conditions model,scheme2 --json");
  ASSERT_EQ(table["columns"].size(), 4u);
  for (const char* name : {"rhb/newton/model", "rhb/lm/model", "rhb/lm/scheme2"}) {
    const auto& c = Column(table, name);
    ASSERT_EQ(c["rows"].size(), 1u);
    EXPECT_EQ(c["rows"][0]["status"], "converged") << name;
    // Scheme 2 (amplitude + pinned auxiliaries) is the same solution as the model's own.
    EXPECT_LT(c["rows"][0]["max_error"].get<double>(), 1e-5) << name;
  }
  // Newton on scheme 2 factorises a Jacobian singular to round-off (1/cond ~1e-16):
  // whether it stalls (the paper's finding) or lands near the solution depends on
  // the LU's last bits (Eigen's converged here, LAPACK's stalls at |F| ~6e-13).
  // Either way the cell is there and says which, with the residual reached.
  const auto& newton = Column(table, "rhb/newton/scheme2")["rows"];
  ASSERT_EQ(newton.size(), 1u);
  EXPECT_LT(newton[0]["residual"].get<double>(), 1e-6);
  if (newton[0]["status"] == "converged")
    EXPECT_LT(newton[0]["max_error"].get<double>(), 1e-5);
  else
    EXPECT_EQ(newton[0]["status"], "not_converged");
  EXPECT_EQ(Column(table, "rhb/lm/model")["solver"], "lm");
}

TEST(Convergence, RelativisticAmplitudeMatchesThePaper) {
  // Paper Table 2: N = 25 amplitude error 4.36e-7, N = 35 1.95e-9.
  const auto table = Json("convergence relativistic --orders 25,35 --methods rhb --json");
  const auto& rows = Column(table, "rhb")["rows"];
  EXPECT_NEAR(rows[0]["amplitude_error"].get<double>(), 4.36e-7, 0.05e-7);
  EXPECT_NEAR(rows[1]["amplitude_error"].get<double>(), 1.95e-9, 0.05e-9);
}

TEST(Convergence, QuasiPeriodicOrdersAgainstCvode) {
  // No exact reference: the error is CVODE's trajectory started on the
  // solution; taylor/original are periodic-only and not default columns.
  const auto table = Json("convergence duffing-2tone --p 2:3 --json");
  EXPECT_EQ(table["orders"], nlohmann::json({2, 3}));
  EXPECT_EQ(table["columns"].size(), 3u);
  const auto& rhb = Column(table, "rhb")["rows"];
  for (const auto& r : rhb) {
    EXPECT_EQ(r["status"], "converged");
    EXPECT_EQ(r["error"], r["trajectory_error"]);
    EXPECT_TRUE(r["frequency_error"].is_null());
  }
  EXPECT_LT(rhb[1]["trajectory_error"].get<double>(), rhb[0]["trajectory_error"].get<double>());
  const auto orig = Json("convergence duffing-2tone --p 2 --methods original --json");
  EXPECT_NE(Column(orig, "original")["unavailable"].get<std::string>().find("periodic"), std::string::npos);
}

TEST(Convergence, TextTableAndBadInput) {
  const auto r = Cli("convergence pendulum --orders 5,10 --methods rhb,hdhb");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("rhb"), std::string::npos);
  EXPECT_NE(r.out.find("hdhb"), std::string::npos);
  EXPECT_NE(r.out.find("exact"), std::string::npos);
  const auto bad_orders = Cli("convergence pendulum --orders 5:x");
  EXPECT_EQ(bad_orders.code, 2);
  EXPECT_NE(bad_orders.out.find("--orders"), std::string::npos) << bad_orders.out;
  EXPECT_EQ(Cli("convergence pendulum --orders 0:5").code, 2);
  const auto bad_method = Cli("convergence pendulum --methods rhb,foo");
  EXPECT_EQ(bad_method.code, 2);
  EXPECT_NE(bad_method.out.find("foo"), std::string::npos);
  EXPECT_EQ(Cli("convergence pendulum --solver newton,gauss").code, 2);
  EXPECT_EQ(Cli("convergence pendulum --conditions scheme9").code, 2);
  EXPECT_EQ(Cli("convergence duffing --conditions scheme3 --orders 5").code, 2);  // no such conditions
}

}  // namespace

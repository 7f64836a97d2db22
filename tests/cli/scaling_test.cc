// `--scaling`: a MEMS Duffing resonator in SI units
// (examples/models/mems-duffing.yaml) against the same physics in good units
// (examples/models/duffing.yaml: x = 1e-6 X, t = T / 1e4), and against a
// tight CVODE trajectory of its own equations.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/cli_run.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace {

using rmhb::testing::Cli;
using rmhb::testing::Json;
using nlohmann::json;

constexpr double kMetresPerUnit = 1e-6, kRadiansPerSecondPerUnit = 1e4;

// Largest difference of x's coefficients, SI mapped back to the
// nondimensional units, relative to the largest coefficient.
double MappedCoefficientError(const json& si, const json& nondimensional) {
  double error = 0, size = 0;
  for (const char* part : {"cos", "sin"}) {
    const auto& a = nondimensional["coefficients"]["x"][part];
    const auto& b = si["coefficients"]["x"][part];
    EXPECT_EQ(a.size(), b.size());
    for (size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
      error = std::max(error, std::abs(b[k].get<double>() / kMetresPerUnit - a[k].get<double>()));
      size = std::max(size, std::abs(a[k].get<double>()));
    }
  }
  return error / size;
}

TEST(CliScaling, SiUnitsGiveTheNondimensionalSolutionToRoundOff) {
  const std::string order = " --order 30 --json";
  const json reference = Json("solve examples/models/duffing.yaml" + order);
  const json si = Json("solve examples/models/mems-duffing.yaml" + order);  // default: equilibrate
  ASSERT_EQ(reference["status"], "converged") << reference.dump();
  ASSERT_EQ(si["status"], "converged") << si.dump();
  EXPECT_EQ(si["scaling"], "equilibrate");
  EXPECT_LT(MappedCoefficientError(si, reference), 1e-12);
  EXPECT_NEAR(si["frequencies"][0].get<double>() / kRadiansPerSecondPerUnit,
              reference["frequencies"][0].get<double>(), 1e-15);
  // The units made J look 100 times worse conditioned than it is.
  EXPECT_GT(si["scaled_reciprocal_condition"].get<double>(),
            10 * si["reciprocal_condition"].get<double>());
  // The old absolute test max|F| <= 1e-15 is met early by forces of 1e-7 N.
  // Measured from the guess alone: 1e-10; warm-started through the coarse
  // orders (Newton's last step from closer): 7.0e-14, against 3.5e-16
  // equilibrated.
  const json none = Json("solve examples/models/mems-duffing.yaml --scaling none" + order);
  ASSERT_EQ(none["status"], "converged") << none.dump();
  EXPECT_EQ(none["scaling"], "none");
  EXPECT_GT(MappedCoefficientError(none, reference), 1e-14);
  EXPECT_EQ(none["scaled_reciprocal_condition"], none["reciprocal_condition"]);
}

// Independent of the nondimensional solve: CVODE (rtol 1e-13) integrates the
// SI equations from the solution's state at t = 0 over one period. The
// largest state is the velocity, 2e4 rad/s x 2 um = 4e-2 m/s.
TEST(CliScaling, SiSolutionMatchesCvodeToItsOwnRelativeAccuracy) {
  const std::string args = "solve examples/models/mems-duffing.yaml --order 30 --validate --json";
  const json scaled = Json(args + " --scaling equilibrate");
  ASSERT_EQ(scaled["validation"]["status"], "ok") << scaled.dump();
  // CVODE's own error (rtol 1e-13) decides this number, not the solution's:
  // measured 1.6e-13 equilibrated and 2.0e-12 unscaled with OpenBLAS's LU,
  // 1.9e-12 and 1.1e-13 with Eigen's (DenseLu below kMaxEigenLuDimension,
  // the coarse orders), while the coefficients stayed 3.5e-16 / 4.1e-16
  // (equilibrated) and 7.0e-14 / 7.1e-14 (unscaled) from the nondimensional
  // solve; the ASan (RelWithDebInfo) build measured 2.3e-12 equilibrated. So
  // both are held to CVODE's accuracy with room, 5e-10 of the velocity; the
  // test above is the one that tells the scalings apart.
  EXPECT_LT(scaled["validation"]["max_error"].get<double>(), 4e-2 * 5e-10);
  const json none = Json(args + " --scaling none");
  ASSERT_EQ(none["validation"]["status"], "ok") << none.dump();
  EXPECT_LT(none["validation"]["max_error"].get<double>(), 4e-2 * 5e-10);
}

TEST(CliScaling, TextReportAndBadValues) {
  const auto run = Cli("solve examples/models/mems-duffing.yaml --order 10 --scaling equilibrate");
  ASSERT_EQ(run.code, 0) << run.out;
  EXPECT_NE(run.out.find("equilibrated D_r J D_c"), std::string::npos) << run.out;
  const auto bad = Cli("solve duffing --scaling ruiz");
  EXPECT_EQ(bad.code, 1) << bad.out;
  EXPECT_NE(bad.out.find("--scaling"), std::string::npos) << bad.out;
  EXPECT_NE(Cli("solve --help").out.find("--scaling"), std::string::npos);
}

}  // namespace

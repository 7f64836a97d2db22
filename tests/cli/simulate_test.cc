// `rmhb simulate`: the CSV of the original equations against the exact
// pendulum solution (nome series), and its errors.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "examples/references.h"
#include "tests/cli/cli_run.h"

namespace {

using rmhb::testing::Cli;
using rmhb::testing::Json;

std::vector<std::vector<double>> ReadCsv(const std::string& file, std::string* header) {
  std::ifstream in(file);
  std::getline(in, *header);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

TEST(Simulate, PendulumCsvMatchesTheExactSolution) {
  const std::string csv = ::testing::TempDir() + "simulate_pendulum.csv";
  const auto j = Json("simulate pendulum --set theta0=1.2 --t-end 20 --dt 0.5 --csv " + csv + " --json");
  EXPECT_EQ(j["status"], "ok");
  EXPECT_EQ(j["rows"], 41);
  std::string header;
  const auto rows = ReadCsv(csv, &header);
  EXPECT_EQ(header, "t,theta,theta'");
  ASSERT_EQ(rows.size(), 41u);
  for (size_t i = 0; i < rows.size(); i += 5) {
    EXPECT_DOUBLE_EQ(rows[i][0], 0.5 * i);
    EXPECT_NEAR(rows[i][1], rmhb::examples::PendulumAngle(1.2, rows[i][0]), 1e-9) << "t = " << rows[i][0];
  }
  // theta' by a central difference of the exact solution.
  const double t = rows[8][0], h = 1e-4;
  EXPECT_NEAR(rows[8][2],
              (rmhb::examples::PendulumAngle(1.2, t + h) - rmhb::examples::PendulumAngle(1.2, t - h)) / (2 * h),
              1e-7);
}

TEST(Simulate, ModelFileAndStandardOutput) {
  // Relativistic oscillator from x = 0, x' = beta: the energy gamma + x^2/2
  // is conserved along the CSV rows (to CVODE's accuracy at rtol 1e-12).
  const auto r = Cli("simulate examples/models/relativistic.yaml --t-end 8 --dt 2");
  ASSERT_EQ(r.code, 0) << r.out;
  std::stringstream lines(r.out);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "t,x,x'");
  int rows = 0;
  while (std::getline(lines, line)) {
    double t, x, v;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf", &t, &x, &v), 3) << line;
    EXPECT_NEAR(1 / std::sqrt(1 - v * v) + x * x / 2, 1 / std::sqrt(1 - 0.85 * 0.85), 1e-9) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 5);
}

TEST(Simulate, ModelFileResultsRepeatBitForBit) {
  // GiNaC orders a sum's terms by hashes that move with the address layout;
  // the compiled equations must not, or every run differs in the last bits.
  const std::string args = "simulate examples/models/duffing.yaml --t-end 6 --dt 0.5";
  const std::string first = Cli(args).out;
  for (int run = 0; run < 4; ++run) EXPECT_EQ(Cli(args).out, first) << "run " << run;
}

TEST(Simulate, DaeModelGoesToIdaAndConservesTheEnergy) {
  // x'' + x z = 0 with z (1 + x^2) = 1 (algebraic): IDA. Along the rows the
  // energy x'^2/2 + log(1 + x^2)/2 stays log(1 + A^2)/2, and z meets its
  // constraint, both to IDA's accuracy (its Newton stops near 1e-10).
  const std::string csv = ::testing::TempDir() + "simulate_dae.csv";
  const auto j = Json("simulate examples/models/softening-dae.yaml --t-end 10 --dt 0.5 --csv " + csv + " --json");
  EXPECT_EQ(j["status"], "ok");
  EXPECT_NE(j["integrator"].get<std::string>().find("IDA"), std::string::npos) << j.dump();
  std::string header;
  const auto rows = ReadCsv(csv, &header);
  EXPECT_EQ(header, "t,x,x',z");
  ASSERT_EQ(rows.size(), 21u);
  const double A = 1.5;
  for (const auto& row : rows) {
    const double x = row[1], v = row[2], z = row[3];
    EXPECT_NEAR(v * v / 2 + std::log(1 + x * x) / 2, std::log(1 + A * A) / 2, 1e-8) << "t = " << row[0];
    EXPECT_NEAR(z * (1 + x * x), 1, 1e-8) << "t = " << row[0];
  }
  EXPECT_DOUBLE_EQ(rows[0][1], A);
}

TEST(Simulate, BlowUpStopsWithExitCode3AndTheRowsReached) {
  // x' = x^2, x(0) = 1: x = 1/(1 - t) blows up at t = 1.
  const std::string model = ::testing::TempDir() + "simulate_blowup.yaml";
  std::ofstream(model) << "name: blowup\nvariables: [x]\nequations:\n  - \"x' = x^2\"\n"
                          "frequencies:\n  - {guess: 1}\ninitial_state: {x: 1}\nguess: {x: \"1\"}\n";
  const std::string csv = ::testing::TempDir() + "simulate_blowup.csv";
  const auto r = Cli("simulate " + model + " --t-end 2 --dt 0.25 --csv " + csv);
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("integration failed"), std::string::npos) << r.out;
  std::string header;
  const auto rows = ReadCsv(csv, &header);
  ASSERT_EQ(rows.size(), 4u);  // t = 0, 0.25, 0.5, 0.75
  for (const auto& row : rows) EXPECT_NEAR(row[1], 1 / (1 - row[0]), 1e-8) << row[0];
}

TEST(Simulate, BadInputIsRefused) {
  EXPECT_EQ(Cli("simulate pendulum --dt 0").code, 2);
  EXPECT_EQ(Cli("simulate pendulum --t-end -1").code, 2);
  EXPECT_EQ(Cli("simulate pendulum --t-end 1e9 --dt 1e-3").code, 2);
  EXPECT_EQ(Cli("simulate nosuchmodel").code, 2);
  EXPECT_EQ(Cli("simulate pendulum --rtol 0").code, 2);
  EXPECT_EQ(Cli("simulate pendulum --json").code, 2);  // the data needs --csv
  EXPECT_EQ(Cli("simulate pendulum --csv /nonexistent/dir/x.csv").code, 2);
}

}  // namespace

#include "frequency_id/sinusoid_fit.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "frequency_id/window.h"

namespace rmhb::frequency_id {
namespace {

Eigen::MatrixXd Lines(const SampleGrid& grid, const std::vector<double>& omegas,
                      const std::vector<double>& amplitudes, double mean) {
  Eigen::MatrixXd x = Eigen::MatrixXd::Constant(grid.size, 1, mean);
  for (std::size_t k = 0; k < omegas.size(); ++k) {
    for (int n = 0; n < grid.size; ++n) {
      x(n, 0) += amplitudes[k] * std::cos(omegas[k] * (grid.t0 + n * grid.dt) + 0.5 * k);
    }
  }
  return x;
}

// Two lines half a bin apart, started a quarter bin off: only a joint
// (block) Gauss-Newton step untangles them; one line at a time crawls.
TEST(SinusoidFitter, ResolvesLinesHalfABinApart) {
  const SampleGrid grid{0.0, 0.25, 8192};
  const double bin = grid.BinWidth();
  const std::vector<double> omegas{1.3, 1.3 + 0.5 * bin};
  const Eigen::MatrixXd x = Lines(grid, omegas, {1.0, 0.7}, 0.25);
  SinusoidFitter fitter(grid, x, Window(1).Sample(grid.size));
  fitter.AddLine(omegas[0] - 0.25 * bin);
  fitter.AddLine(omegas[1] + 0.2 * bin);
  PolishOptions options;
  options.cluster_spacing = 4.0 * bin;
  const PolishSummary summary = fitter.Polish(options);
  EXPECT_TRUE(summary.converged);
  EXPECT_EQ(summary.largest_cluster, 2);
  ASSERT_TRUE(fitter.FitAllCoefficients());
  const SinusoidModel& model = fitter.model();
  EXPECT_NEAR(model.frequencies[0], omegas[0], 1e-13);
  EXPECT_NEAR(model.frequencies[1], omegas[1], 1e-13);
  EXPECT_NEAR(model.Amplitude(0), 1.0, 1e-10);
  EXPECT_NEAR(model.Amplitude(1), 0.7, 1e-10);
  EXPECT_NEAR(model.mean(0), 0.25, 1e-12);
  EXPECT_LT(fitter.WeightedResidualRms()(0), 1e-12);
}

TEST(SinusoidFitter, RemoveLineRestoresTheResidual) {
  const SampleGrid grid{1.0, 0.5, 2048};
  const Eigen::MatrixXd x = Lines(grid, {0.9, 2.1}, {1.0, 0.3}, 0.0);
  SinusoidFitter fitter(grid, x, Window(2).Sample(grid.size));
  fitter.AddLine(0.9);
  const Eigen::MatrixXd after_one = fitter.residual();
  fitter.AddLine(2.1);
  fitter.RemoveLine(1);
  EXPECT_EQ(fitter.num_lines(), 1);
  EXPECT_LT((fitter.residual() - after_one).cwiseAbs().maxCoeff(), 1e-12);
}

// The reported standard error must describe the actual scatter over noise
// realisations (the sandwich formula accounts for the window weights).
TEST(SinusoidFitter, StandardErrorMatchesMonteCarloScatter) {
  const SampleGrid grid{0.0, 0.5, 4096};
  const double omega = 1.1;
  const double noise = 1e-3;
  const Eigen::MatrixXd clean = Lines(grid, {omega}, {1.0}, 0.0);
  std::mt19937_64 generator(99);
  std::normal_distribution<double> normal(0.0, noise);
  double sum_squared_error = 0.0, sum_reported = 0.0;
  const int trials = 40;
  for (int trial = 0; trial < trials; ++trial) {
    Eigen::MatrixXd x = clean;
    for (int n = 0; n < grid.size; ++n) x(n, 0) += normal(generator);
    SinusoidFitter fitter(grid, x, Window(2).Sample(grid.size));
    fitter.AddLine(omega);
    fitter.Polish(PolishOptions());
    const double error = fitter.model().frequencies[0] - omega;
    sum_squared_error += error * error;
    sum_reported += fitter.FrequencyStandardErrors(0.0)[0];
  }
  const double scatter = std::sqrt(sum_squared_error / trials);
  const double reported = sum_reported / trials;
  std::printf("[ standard error ] Monte Carlo %.3e, reported %.3e\n", scatter, reported);
  EXPECT_GT(reported, 0.6 * scatter);
  EXPECT_LT(reported, 1.6 * scatter);
}

}  // namespace
}  // namespace rmhb::frequency_id

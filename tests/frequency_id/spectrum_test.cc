#include "frequency_id/spectrum.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace rmhb::frequency_id {
namespace {

TEST(SpectrumAnalyzer, LineOnABinReadsItsAmplitude) {
  const SampleGrid grid{0.0, 0.1, 4096};
  SpectrumAnalyzer analyzer(grid, Window(2));
  const int bin = 300;
  const double omega = bin * grid.BinWidth();
  Eigen::MatrixXd x(grid.size, 2);
  for (int n = 0; n < grid.size; ++n) {
    x(n, 0) = 0.8 * std::cos(omega * n * grid.dt + 0.4);
    x(n, 1) = 0.6 * std::sin(omega * n * grid.dt);
  }
  analyzer.Compute(x);
  // Two channels: the norm of their amplitudes, sqrt(0.8^2 + 0.6^2) = 1.
  EXPECT_NEAR(analyzer.amplitudes()(bin), 1.0, 1e-3);
  const std::vector<SpectralPeak> peaks = analyzer.FindPeaks({});
  ASSERT_FALSE(peaks.empty());
  EXPECT_EQ(peaks[0].bin, bin);
  EXPECT_DOUBLE_EQ(peaks[0].frequency, omega);
}

TEST(SpectrumAnalyzer, PeaksStrongestFirstWithinTheBand) {
  const SampleGrid grid{2.0, 0.05, 8192};
  SpectrumAnalyzer analyzer(grid, Window(1));
  Eigen::MatrixXd x(grid.size, 1);
  const double w1 = 3.1, w2 = 7.7, w3 = 20.3;
  for (int n = 0; n < grid.size; ++n) {
    const double t = grid.t0 + n * grid.dt;
    x(n, 0) = 0.1 * std::cos(w1 * t) + 1.0 * std::cos(w2 * t) + 0.01 * std::cos(w3 * t);
  }
  analyzer.Compute(x);
  PeakSearchOptions options;
  options.min_amplitude = 1e-3;
  std::vector<SpectralPeak> peaks = analyzer.FindPeaks(options);
  ASSERT_GE(peaks.size(), 3u);
  EXPECT_NEAR(peaks[0].frequency, w2, grid.BinWidth());
  EXPECT_NEAR(peaks[1].frequency, w1, grid.BinWidth());
  EXPECT_NEAR(peaks[2].frequency, w3, grid.BinWidth());
  for (std::size_t i = 1; i < peaks.size(); ++i) {
    EXPECT_GE(peaks[i - 1].amplitude, peaks[i].amplitude);
  }
  options.max_frequency = 10.0;
  options.max_peaks = 1;
  peaks = analyzer.FindPeaks(options);
  ASSERT_EQ(peaks.size(), 1u);
  EXPECT_NEAR(peaks[0].frequency, w2, grid.BinWidth());
  options.min_frequency = 10.0;
  options.max_frequency = INFINITY;
  peaks = analyzer.FindPeaks(options);
  ASSERT_EQ(peaks.size(), 1u);
  EXPECT_NEAR(peaks[0].frequency, w3, grid.BinWidth());
}

TEST(SpectrumAnalyzer, MedianIsTheNoiseFloor) {
  const SampleGrid grid{0.0, 1.0, 16384};
  SpectrumAnalyzer analyzer(grid, Window(1));
  std::mt19937_64 generator(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd x(grid.size, 1);
  for (int n = 0; n < grid.size; ++n) x(n, 0) = normal(generator) + 5.0 * std::cos(0.7 * n);
  analyzer.Compute(x);
  // |phi| of white noise is Rayleigh with scale sigma sqrt(sum w^2 / 2) / sum w
  // (sum w^2 / (sum w)^2 = 1.5 / N for Hann): A = 2|phi| has median
  // 2 sqrt(2 ln 2) * sigma * sqrt(0.75 / N). One line barely moves the median.
  const double expected = 2.0 * std::sqrt(2.0 * std::log(2.0)) * std::sqrt(0.75 / grid.size);
  EXPECT_NEAR(analyzer.MedianAmplitude(0.0, INFINITY), expected, 0.05 * expected);
}

}  // namespace
}  // namespace rmhb::frequency_id

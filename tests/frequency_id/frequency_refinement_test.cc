#include "frequency_id/frequency_refinement.h"

#include <cmath>
#include <ostream>
#include <string>

#include <gtest/gtest.h>

#include "frequency_id/window.h"

namespace rmhb::frequency_id {

// Readable parameter values in test names and failure messages.
void PrintTo(RefinementAlgorithm algorithm, std::ostream* os) { *os << ToString(algorithm); }

namespace {

struct Record {
  SampleGrid grid;
  Eigen::MatrixXd windowed;
  double weight_sum;
};

Record MakeRecord(double omega, int order, int channels = 1) {
  Record r;
  r.grid = SampleGrid{-3.0, 0.2, 8000};
  const Eigen::VectorXd w = Window(order).Sample(r.grid.size);
  r.weight_sum = w.sum();
  r.windowed.resize(r.grid.size, channels);
  for (int n = 0; n < r.grid.size; ++n) {
    const double t = r.grid.t0 + n * r.grid.dt;
    for (int c = 0; c < channels; ++c) {
      r.windowed(n, c) = w(n) * (1.0 + c) * std::cos(omega * t + 0.3 + c) +
                         w(n) * 0.2 * std::cos(2.9 * omega * t);
    }
  }
  return r;
}

TEST(LinePower, DerivativesMatchFiniteDifferences) {
  const Record r = MakeRecord(1.234567, 2, 2);
  const double omega = 1.2347;
  const double h = 1e-6;
  const LinePower p = EvaluateLinePower(r.grid, r.windowed, r.weight_sum, omega);
  const LinePower plus = EvaluateLinePower(r.grid, r.windowed, r.weight_sum, omega + h);
  const LinePower minus = EvaluateLinePower(r.grid, r.windowed, r.weight_sum, omega - h);
  EXPECT_NEAR(p.first, (plus.value - minus.value) / (2 * h), 1e-6 * std::abs(p.first) + 1e-9);
  EXPECT_NEAR(p.second, (plus.first - minus.first) / (2 * h), 1e-6 * std::abs(p.second));
}

class RefineLine : public ::testing::TestWithParam<RefinementAlgorithm> {};

// A derivative-free maximiser stalls near sqrt(eps); every NLopt algorithm
// followed by Newton on dS/domega must reach round-off (plus the tiny bias
// of the mirror line at -omega, far below 1e-14 at order 2).
TEST_P(RefineLine, ReachesRoundOffFromAPeakBin) {
  const double omega = 1.2345678912345;
  const Record r = MakeRecord(omega, 2);
  const double bin = r.grid.BinWidth();
  const double start = std::round(omega / bin) * bin;
  RefinementOptions options;
  options.algorithm = GetParam();
  const RefinedLine line =
      RefineLineFrequency(r.grid, r.windowed, r.weight_sum, start - bin, start + bin, start,
                          options);
  EXPECT_TRUE(line.converged);
  EXPECT_NEAR(line.frequency, omega, 1e-14 * omega) << ToString(GetParam());
  EXPECT_NEAR(line.amplitude, 1.0, 1e-9);
  EXPECT_LT(line.evaluations, 40);
}

INSTANTIATE_TEST_SUITE_P(AllAlgorithms, RefineLine,
                         ::testing::Values(RefinementAlgorithm::kMMA, RefinementAlgorithm::kCCSAQ,
                                           RefinementAlgorithm::kSLSQP,
                                           RefinementAlgorithm::kLBFGS),
                         [](const ::testing::TestParamInfo<RefinementAlgorithm>& info) {
                           std::string name = ToString(info.param);
                           return name.substr(3);
                         });

TEST(RefineLine, SeveralChannelsShareTheFrequency) {
  const double omega = 2.2222222222;
  const Record r = MakeRecord(omega, 3, 3);
  const double bin = r.grid.BinWidth();
  const double start = std::round(omega / bin) * bin;
  const RefinedLine line =
      RefineLineFrequency(r.grid, r.windowed, r.weight_sum, start - bin, start + bin, start);
  EXPECT_NEAR(line.frequency, omega, 1e-14 * omega);
  // sqrt(1 + 4 + 9)
  EXPECT_NEAR(line.amplitude, std::sqrt(14.0), 1e-9);
}

}  // namespace
}  // namespace rmhb::frequency_id

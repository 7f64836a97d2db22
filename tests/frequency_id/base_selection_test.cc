#include "frequency_id/base_selection.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "synthetic_signal.h"

namespace rmhb::frequency_id {
namespace {

struct TrueLine {
  std::vector<int> label;
  double amplitude;
};

std::vector<LineEstimate> MakeLines(const std::vector<double>& bases,
                                    const std::vector<TrueLine>& truth, double sigma = 1e-15) {
  std::vector<LineEstimate> lines;
  for (const TrueLine& t : truth) {
    double f = 0.0;
    for (std::size_t i = 0; i < bases.size(); ++i) f += t.label[i] * bases[i];
    EXPECT_GT(f, 0.0) << "test lines must have positive frequencies";
    lines.push_back({f, sigma, 0.5 * t.amplitude * t.amplitude});
  }
  return lines;
}

void ExpectLabels(const BaseSelection& selection, const std::vector<TrueLine>& truth) {
  ASSERT_EQ(selection.labels.size(), truth.size());
  for (std::size_t k = 0; k < truth.size(); ++k) {
    EXPECT_EQ(selection.labels[k], truth[k].label) << "line " << k;
  }
}

using testing::kW1;
using testing::kW2;

// (1,1) and (2,0) are stronger than the base w2: picking bases by amplitude
// would take w1 and 2 w1, or w1 and w1 + w2.
TEST(SelectBases, CombinationToneStrongerThanABase) {
  const std::vector<TrueLine> truth{
      {{1, 0}, 1.0},   {{2, 0}, 0.3},   {{1, 1}, 0.12},  {{0, 1}, 0.05},  {{2, -1}, 0.03},
      {{3, 0}, 0.02},  {{-1, 2}, 0.01}, {{2, 1}, 8e-3},  {{1, 2}, 4e-3},  {{0, 2}, 2e-3},
      {{3, -1}, 1e-3}, {{-1, 1}, 3e-4}, {{3, 1}, 5e-4},  {{4, 0}, 2e-6},  {{0, 3}, 1e-6}};
  BaseSelection selection;
  ASSERT_TRUE(SelectBases(MakeLines({kW1, kW2}, truth), BaseSelectionOptions(), &selection));
  ASSERT_EQ(selection.bases.size(), 2u) << selection.message;
  EXPECT_NEAR(selection.bases[0].frequency, kW1, 1e-14);
  EXPECT_NEAR(selection.bases[1].frequency, kW2, 1e-14);
  EXPECT_EQ(selection.bases[0].line, 0);
  EXPECT_EQ(selection.bases[1].line, 3);
  ExpectLabels(selection, truth);
  EXPECT_EQ(selection.num_explained, static_cast<int>(truth.size()));
}

// A near-resonant ladder w1 - k (w2 - w1), the (2,-1) tone stronger than w2:
// the label set alone is more compact in the sheared coordinates
// (w2 - w1, w1), and the amplitude-weighted label norm prefers them too;
// the robust fit of the amplitudes' decay does not.
TEST(SelectBases, NearResonantLadder) {
  const std::vector<TrueLine> truth{
      {{1, 0}, 1.0},   {{2, 0}, 0.3},   {{2, -1}, 0.12}, {{0, 1}, 0.05},  {{3, 0}, 0.05},
      {{1, 1}, 0.04},  {{-1, 2}, 0.02}, {{3, -1}, 0.01}, {{2, 1}, 5e-3},  {{0, 2}, 2e-3},
      {{3, -2}, 1e-3}, {{-1, 1}, 3e-4}, {{-2, 3}, 1e-4}, {{4, -3}, 1e-5}, {{4, -1}, 2e-6},
      {{5, -4}, 1e-6}, {{4, 0}, 1e-6}};
  BaseSelection selection;
  ASSERT_TRUE(SelectBases(MakeLines({kW1, kW2}, truth), BaseSelectionOptions(), &selection));
  ASSERT_EQ(selection.bases.size(), 2u);
  EXPECT_NEAR(selection.bases[0].frequency, kW1, 1e-14);
  EXPECT_NEAR(selection.bases[1].frequency, kW2, 1e-14);
  ExpectLabels(selection, truth);
}

TEST(SelectBases, PeriodicSignalHasOneBase) {
  const double w = 0.3141;
  std::vector<TrueLine> truth;
  // Harmonics up to 25 > max_order: a single base may go to max_harmonic.
  for (int n = 1; n <= 25; n += 2) truth.push_back({{n}, std::pow(0.5, n)});
  BaseSelection selection;
  ASSERT_TRUE(SelectBases(MakeLines({w}, truth), BaseSelectionOptions(), &selection));
  ASSERT_EQ(selection.bases.size(), 1u) << selection.message;
  EXPECT_NEAR(selection.bases[0].frequency, w, 1e-15);
  ExpectLabels(selection, truth);
}

// A dry-friction or contact cycle: odd harmonics to 63 and beyond, slowly
// decaying (at max_harmonic 40 the 12 beyond 39 were unexplained lines, and
// `identify` said unexplained_components on a periodic record).
TEST(SelectBases, AKinkedCyclesHighHarmonicsAreAllLabelled) {
  const double w = 0.8;
  std::vector<TrueLine> truth;
  for (int n = 1; n <= 75; n += 2) truth.push_back({{n}, 1.0 / (n * n)});
  BaseSelection selection;
  ASSERT_TRUE(SelectBases(MakeLines({w}, truth, 1e-13), BaseSelectionOptions(), &selection));
  ASSERT_EQ(selection.bases.size(), 1u) << selection.message;
  EXPECT_EQ(selection.num_explained, static_cast<int>(truth.size()));
  ExpectLabels(selection, truth);
}

TEST(SelectBases, MissingFundamentalIsTheCommonDivisor) {
  const double w = 0.41;
  const std::vector<TrueLine> truth{{{2}, 1.0}, {{3}, 0.5}, {{5}, 0.1}};
  BaseSelection selection;
  ASSERT_TRUE(SelectBases(MakeLines({w}, truth), BaseSelectionOptions(), &selection));
  ASSERT_EQ(selection.bases.size(), 1u);
  EXPECT_NEAR(selection.bases[0].frequency, w, 1e-15);
  EXPECT_EQ(selection.bases[0].line, -1);  // not itself a line
  ExpectLabels(selection, truth);
}

TEST(SelectBases, KnownFrequencyIsKeptExactlyAndFirst) {
  const double forcing = 1.3;
  const double autonomous = 0.4123456789012;
  // The forcing line itself is absent: only combinations carry it.
  const std::vector<TrueLine> truth{{{0, 1}, 1.0},  {{1, -1}, 0.2}, {{0, 2}, 0.1},
                                    {{1, 1}, 0.04}, {{0, 3}, 0.01}, {{1, -2}, 5e-3}};
  BaseSelectionOptions options;
  options.known_frequencies = {forcing};
  BaseSelection selection;
  ASSERT_TRUE(SelectBases(MakeLines({forcing, autonomous}, truth), options, &selection));
  ASSERT_EQ(selection.bases.size(), 2u);
  EXPECT_EQ(selection.bases[0].frequency, forcing);
  EXPECT_TRUE(selection.bases[0].known);
  EXPECT_EQ(selection.bases[0].line, -1);
  EXPECT_NEAR(selection.bases[1].frequency, autonomous, 1e-14);
  ExpectLabels(selection, truth);
}

TEST(SelectBases, ThreeBases) {
  const std::vector<double> bases{0.6180339887, 0.9718281828, 1.4142135624};
  const std::vector<TrueLine> truth{{{1, 0, 0}, 1.0},  {{0, 1, 0}, 0.5},  {{0, 0, 1}, 0.3},
                                    {{1, 1, 0}, 0.05}, {{0, 1, 1}, 0.04}, {{-1, 0, 1}, 0.03},
                                    {{2, 0, 0}, 0.02}};
  BaseSelectionOptions options;
  options.max_bases = 3;
  BaseSelection selection;
  ASSERT_TRUE(SelectBases(MakeLines(bases, truth), options, &selection));
  ASSERT_EQ(selection.bases.size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(selection.bases[i].frequency, bases[i], 1e-14);
  ExpectLabels(selection, truth);

  // With only two bases allowed, the lines needing the third stay unlabelled.
  options.max_bases = 2;
  ASSERT_TRUE(SelectBases(MakeLines(bases, truth), options, &selection));
  EXPECT_EQ(selection.bases.size(), 2u);
  EXPECT_LT(selection.num_explained, 7);
  EXPECT_LT(selection.explained_energy_fraction, 1.0);
}

// A weak unrelated line (noise) must not become a base; a strong one must.
TEST(SelectBases, NewBaseNeedsEnergyOrMoreThanItself) {
  const double w = 0.7;
  std::vector<TrueLine> truth;
  for (int n = 1; n <= 5; ++n) truth.push_back({{n}, std::pow(0.1, n - 1)});
  std::vector<LineEstimate> lines = MakeLines({w}, truth);
  lines.push_back({1.2345678, 1e-10, 0.5 * 1e-8 * 1e-8});
  BaseSelection selection;
  ASSERT_TRUE(SelectBases(lines, BaseSelectionOptions(), &selection));
  EXPECT_EQ(selection.bases.size(), 1u);
  EXPECT_TRUE(selection.labels.back().empty());
  EXPECT_TRUE(std::isnan(selection.lattice_residuals.back()));

  lines.back().energy = 0.5 * 0.2 * 0.2;
  ASSERT_TRUE(SelectBases(lines, BaseSelectionOptions(), &selection));
  EXPECT_EQ(selection.bases.size(), 2u);
  EXPECT_EQ(selection.num_explained, 6);
}

// Labels are accepted within tolerance_factor standard errors, no further.
TEST(SelectBases, ToleranceScalesWithTheUncertainty) {
  const std::vector<TrueLine> truth{{{1, 0}, 1.0},  {{0, 1}, 0.5},  {{1, 1}, 0.1},
                                    {{2, 0}, 0.05}, {{-1, 1}, 0.04}, {{0, 2}, 0.02}};
  std::vector<LineEstimate> lines = MakeLines({1.0, 1.6180339887}, truth, 1e-9);
  lines[2].frequency += 5e-9;  // 5 sigma off: still labelled
  lines[3].frequency += 1e-7;  // 100 sigma off: not
  BaseSelection selection;
  ASSERT_TRUE(SelectBases(lines, BaseSelectionOptions(), &selection));
  EXPECT_EQ(selection.labels[2], (std::vector<int>{1, 1}));
  EXPECT_TRUE(selection.labels[3].empty());
}

TEST(SelectBases, RejectsInvalidOptions) {
  BaseSelection selection;
  BaseSelectionOptions options;
  options.max_bases = 4;
  EXPECT_FALSE(SelectBases({}, options, &selection));
  EXPECT_FALSE(selection.message.empty());
  options = BaseSelectionOptions();
  options.known_frequencies = {1.0, 2.0};  // 2 = 2 * 1: dependent
  EXPECT_FALSE(SelectBases({}, options, &selection));
  options.known_frequencies = {-1.0};
  EXPECT_FALSE(SelectBases({}, options, &selection));
}

}  // namespace
}  // namespace rmhb::frequency_id

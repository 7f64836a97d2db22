#include "frequency_id/frequency_identification.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "synthetic_signal.h"

namespace rmhb::frequency_id {
namespace {

using testing::MakeSignal;
using testing::Tone;
using testing::ToneFrequency;

using testing::kW1;
using testing::kW2;

// Amplitudes span 1 .. 1e-6; the sum tone (1,1) (0.12) and the second
// harmonic (0.3) are both stronger than the base w2 (0.05). Combination tones
// come in sign-symmetric pairs (m, n), (m, -n), as in physical spectra.
std::vector<Tone> CloseBaseTones() {
  return {
      {{1, 0}, 1.0, 0.3},    {{2, 0}, 0.3, -0.4},   {{1, 1}, 0.12, 0.7},   {{0, 1}, 0.05, -1.1},
      {{2, -1}, 0.03, 2.5},  {{3, 0}, 0.02, 1.3},   {{-1, 2}, 0.01, 2.0},  {{2, 1}, 8e-3, 0.5},
      {{1, 2}, 4e-3, -0.8},  {{0, 2}, 2e-3, -2.2},  {{3, -1}, 1e-3, 1.7},  {{3, 1}, 5e-4, -3.0},
      {{-1, 1}, 3e-4, 0.9},  {{-2, 3}, 1e-4, -1.4}, {{3, -2}, 1e-4, 2.9},  {{3, 2}, 5e-5, 0.1},
      {{2, 3}, 2e-5, -2.6},  {{4, -1}, 1e-5, -0.2}, {{4, 1}, 1e-5, 1.1},   {{4, 0}, 2e-6, 0.6},
      {{0, 3}, 1e-6, -1.9},
  };
}

struct Check {
  double max_base_error = 0.0;  // relative
  int matched = 0;
  int wrong_labels = 0;
  int extra = 0;
  double max_strong_frequency_error = 0.0;  // relative, lines with amplitude >= 1e-3
};

// Matches every true tone to the identified component nearest in frequency
// and compares labels; bases are compared in the canonical order (ascending).
Check Compare(const IdentificationSummary& summary, const std::vector<double>& bases,
              const std::vector<Tone>& tones) {
  Check check;
  for (std::size_t i = 0; i < bases.size() && i < summary.bases.size(); ++i) {
    check.max_base_error = std::max(
        check.max_base_error, std::abs(summary.bases[i].frequency - bases[i]) / bases[i]);
  }
  std::vector<bool> used(summary.components.size(), false);
  for (const Tone& tone : tones) {
    const double f = ToneFrequency(bases, tone.label);
    int best = -1;
    for (std::size_t k = 0; k < summary.components.size(); ++k) {
      if (best < 0 || std::abs(summary.components[k].frequency - f) <
                          std::abs(summary.components[best].frequency - f)) {
        best = static_cast<int>(k);
      }
    }
    // Far looser than any error here, far tighter than any line spacing.
    if (best < 0 || std::abs(summary.components[best].frequency - f) > 1e-4 * f) continue;
    used[best] = true;
    ++check.matched;
    if (summary.components[best].label != tone.label) {
      ++check.wrong_labels;
      ADD_FAILURE() << "tone at " << f << " labelled wrongly";
    }
    if (tone.amplitude >= 1e-3) {
      check.max_strong_frequency_error = std::max(
          check.max_strong_frequency_error, std::abs(summary.components[best].frequency - f) / f);
    }
  }
  for (bool u : used) check.extra += u ? 0 : 1;
  return check;
}

void Print(const char* name, const IdentificationSummary& summary, const Check& check) {
  std::printf("[ %s ] %d/%zu components, base rel. error %.2e, strong-line rel. error %.2e, "
              "window Hann^%d, %.3f s (detect %.3f, fit %.3f, bases %.3f)\n",
              name, check.matched, summary.components.size(), check.max_base_error,
              check.max_strong_frequency_error, summary.window_order, summary.total_seconds,
              summary.detection_seconds, summary.fitting_seconds, summary.base_selection_seconds);
}

TEST(FrequencyIdentification, CloseBasesWithStrongCombinationTone) {
  const std::vector<double> bases{kW1, kW2};
  const std::vector<Tone> tones = CloseBaseTones();
  const Signal signal = MakeSignal(bases, tones, 0.5, 25600, 3.0, {1.0, 0.5});
  IdentificationSummary summary;
  ASSERT_TRUE(IdentifyFrequencies(IdentificationOptions(), signal, &summary))
      << summary.FullReport();
  const Check check = Compare(summary, bases, tones);
  Print("close bases", summary, check);
  EXPECT_EQ(summary.status, IdentificationStatus::kSuccess) << summary.FullReport();
  ASSERT_EQ(summary.bases.size(), 2u) << summary.FullReport();
  EXPECT_LE(check.max_base_error, 1e-12) << summary.FullReport();
  EXPECT_EQ(check.matched, static_cast<int>(tones.size())) << summary.FullReport();
  EXPECT_EQ(check.wrong_labels, 0);
  EXPECT_EQ(check.extra, 0) << summary.FullReport();
  // The bases are lines of the record, and are reported as such.
  EXPECT_GE(summary.bases[0].line, 0);
  EXPECT_GE(summary.bases[1].line, 0);
  // Amplitudes per channel (gains 1 and 0.5) and phases at t = 0.
  const Component& strongest = summary.components[0];
  EXPECT_EQ(strongest.label, (std::vector<int>{1, 0}));
  EXPECT_NEAR(strongest.amplitude(0), 1.0, 1e-10);
  EXPECT_NEAR(strongest.amplitude(1), 0.5, 1e-10);
  EXPECT_NEAR(strongest.phase(0), 0.3, 1e-9);
  EXPECT_NEAR(strongest.phase(1), 0.6, 1e-9);
  for (const Component& c : summary.components) {
    EXPECT_GT(c.frequency_uncertainty, 0.0);
    EXPECT_LT(std::abs(c.lattice_residual), 1e-9);
  }
  std::printf("%s", summary.FullReport().c_str());
}

TEST(FrequencyIdentification, CloseBasesWithWhiteNoise) {
  const std::vector<double> bases{kW1, kW2};
  const std::vector<Tone> tones = CloseBaseTones();
  const Signal signal = MakeSignal(bases, tones, 0.5, 25600, 3.0, {1.0, 0.5}, 1e-6, 2024);
  IdentificationSummary summary;
  ASSERT_TRUE(IdentifyFrequencies(IdentificationOptions(), signal, &summary))
      << summary.FullReport();
  const Check check = Compare(summary, bases, tones);
  Print("close bases + noise 1e-6", summary, check);
  ASSERT_EQ(summary.bases.size(), 2u) << summary.FullReport();
  EXPECT_LE(check.max_base_error, 1e-8) << summary.FullReport();
  EXPECT_EQ(check.wrong_labels, 0);
  // Every tone well above the noise floor is found.
  EXPECT_GE(check.matched, static_cast<int>(tones.size()) - 3) << summary.FullReport();
  // The reported uncertainty of the strongest line is about right.
  const double f1 = summary.components[0].frequency;
  EXPECT_LT(std::abs(f1 - kW1), 10.0 * summary.components[0].frequency_uncertainty);
}

// All 30 combinations |m| + |n| <= 5 of the two close bases: groups of lines
// 16 bins apart around every harmonic of w1.
TEST(FrequencyIdentification, DenseSpectrumOfThirtyLines) {
  const std::vector<double> bases{kW1, kW2};
  std::vector<Tone> tones;
  for (int m = -5; m <= 5; ++m) {
    for (int n = -5; n <= 5; ++n) {
      const int order = std::abs(m) + std::abs(n);
      if (order == 0 || order > 5 || ToneFrequency(bases, {m, n}) <= 0.0) continue;
      const double amplitude = std::pow(0.1, order - 1) * (1.0 + 0.1 * ((3 * m + 5 * n) % 4));
      tones.push_back({{m, n}, amplitude, 0.37 * m - 0.91 * n});
    }
  }
  ASSERT_EQ(tones.size(), 30u);
  const Signal signal = MakeSignal(bases, tones, 0.5, 25600);
  IdentificationSummary summary;
  ASSERT_TRUE(IdentifyFrequencies(IdentificationOptions(), signal, &summary))
      << summary.FullReport();
  const Check check = Compare(summary, bases, tones);
  Print("dense 30 lines", summary, check);
  EXPECT_EQ(summary.status, IdentificationStatus::kSuccess) << summary.FullReport();
  ASSERT_EQ(summary.bases.size(), 2u);
  EXPECT_LE(check.max_base_error, 1e-12) << summary.FullReport();
  EXPECT_EQ(check.matched, 30) << summary.FullReport();
  EXPECT_EQ(check.extra, 0) << summary.FullReport();
}

// Two lines only 8/T apart (1.27 bins: inside each other's Hann main lobe),
// with a weaker third line and a combination.
TEST(FrequencyIdentification, TwoLinesEightOverTApart) {
  const double duration = 0.5 * 25600;
  const std::vector<double> bases{1.1, 1.1 + 8.0 / duration};
  const std::vector<Tone> tones{
      {{1, 0}, 1.0, 0.2}, {{0, 1}, 0.6, -1.0}, {{1, 1}, 0.01, 0.4}};
  const Signal signal = MakeSignal(bases, tones, 0.5, 25600);
  IdentificationSummary summary;
  ASSERT_TRUE(IdentifyFrequencies(IdentificationOptions(), signal, &summary))
      << summary.FullReport();
  const Check check = Compare(summary, bases, tones);
  Print("two lines 8/T apart", summary, check);
  EXPECT_EQ(summary.window_order, 1);
  ASSERT_EQ(summary.bases.size(), 2u) << summary.FullReport();
  EXPECT_LE(check.max_base_error, 1e-12) << summary.FullReport();
  EXPECT_EQ(check.matched, 3) << summary.FullReport();
  EXPECT_EQ(check.extra, 0) << summary.FullReport();
}

TEST(FrequencyIdentification, PeriodicSignalHasOneBase) {
  const double w0 = 0.7234567891234;
  std::vector<Tone> tones;
  for (int n = 1; n <= 8; ++n) tones.push_back({{n}, std::pow(0.15, n - 1), 0.4 * n});
  const Signal signal = MakeSignal({w0}, tones, 0.25, 16384, -7.0, {1.0}, 0.0, 0, 0.5);
  IdentificationSummary summary;
  ASSERT_TRUE(IdentifyFrequencies(IdentificationOptions(), signal, &summary))
      << summary.FullReport();
  Print("periodic", summary, Compare(summary, {w0}, tones));
  EXPECT_EQ(summary.status, IdentificationStatus::kSuccess) << summary.FullReport();
  ASSERT_EQ(summary.bases.size(), 1u) << summary.FullReport();
  EXPECT_NEAR(summary.bases[0].frequency, w0, 1e-12 * w0);
  ASSERT_EQ(summary.components.size(), 8u) << summary.FullReport();
  for (std::size_t k = 0; k < summary.components.size(); ++k) {
    // Strongest first is also harmonic order here.
    EXPECT_EQ(summary.components[k].label, (std::vector<int>{static_cast<int>(k) + 1}));
  }
  EXPECT_NEAR(summary.mean(0), 0.5, 1e-10);
}

// A record whose frequency drifts (an integrator's phase error, a slowly
// changing system): cos(w t + eps t^2 / 2), the instantaneous frequency
// w + eps t. The joint fit of a stationary line claims ~1e-14; the halves
// of the record see w + eps T / 4 and w + 3 eps T / 4, and the base's
// uncertainty is what they disagree on, eps T / 2 (the exact drift), which
// covers the distance to the mean frequency w + eps T / 2 from its start.
// A stationary record has no drift and keeps its statistical error.
TEST(FrequencyIdentification, ADriftingRecordWidensItsBasesUncertainty) {
  const double w = 1.0, eps = 1e-12, dt = 0.05;
  const int n = 40000;
  const double T = n * dt;
  Signal drifting, steady;
  drifting.dt = steady.dt = dt;
  drifting.samples.resize(n, 1);
  steady.samples.resize(n, 1);
  for (int i = 0; i < n; ++i) {
    const double t = i * dt;
    drifting.samples(i, 0) = std::cos(w * t + 0.5 * eps * t * t);
    steady.samples(i, 0) = std::cos(w * t);
  }
  IdentificationOptions options;
  options.relative_threshold = 1e-5;  // the chirp's own sidebands (~5e-7) are not lines here
  IdentificationSummary d, s;
  ASSERT_TRUE(IdentifyFrequencies(options, drifting, &d)) << d.FullReport();
  ASSERT_TRUE(IdentifyFrequencies(options, steady, &s)) << s.FullReport();
  ASSERT_EQ(d.bases.size(), 1u);
  ASSERT_EQ(s.bases.size(), 1u);
  EXPECT_NEAR(d.bases[0].drift, eps * T / 2, 0.05 * eps * T / 2);
  EXPECT_EQ(d.bases[0].uncertainty, d.bases[0].drift);
  EXPECT_LE(std::abs(d.bases[0].frequency - (w + eps * T / 2)), d.bases[0].uncertainty);
  EXPECT_NE(d.FullReport().find("halves disagree"), std::string::npos);
  EXPECT_EQ(s.bases[0].drift, 0.0);
  EXPECT_LT(s.bases[0].uncertainty, 1e-13);
  EXPECT_NEAR(s.bases[0].frequency, w, 1e-13);
}

// A forced response: the forcing frequency is weak in the record and the
// autonomous frequency is not a rational multiple of it. The forcing must be
// kept as the first base, exactly as given.
TEST(FrequencyIdentification, KnownForcingFrequencyIsKeptAsBase) {
  const double forcing = 1.3;
  const double autonomous = 0.4123456789012;
  const std::vector<double> bases{forcing, autonomous};
  const std::vector<Tone> tones{
      {{0, 1}, 1.0, 0.1},   {{1, -1}, 0.2, 0.5},  {{0, 2}, 0.1, 1.0},  {{1, 0}, 0.05, -0.7},
      {{1, 1}, 0.04, -2.0}, {{0, 3}, 0.01, 0.3},  {{1, -2}, 5e-3, 1.5}, {{2, -1}, 1e-4, -1.0},
  };
  const Signal signal = MakeSignal(bases, tones, 0.5, 16384);
  IdentificationOptions options;
  options.bases.known_frequencies = {forcing};
  IdentificationSummary summary;
  ASSERT_TRUE(IdentifyFrequencies(options, signal, &summary)) << summary.FullReport();
  const Check check = Compare(summary, bases, tones);
  Print("forced", summary, check);
  EXPECT_EQ(summary.status, IdentificationStatus::kSuccess) << summary.FullReport();
  ASSERT_EQ(summary.bases.size(), 2u);
  EXPECT_EQ(summary.bases[0].frequency, forcing);
  EXPECT_TRUE(summary.bases[0].known);
  EXPECT_FALSE(summary.bases[1].known);
  EXPECT_LE(check.max_base_error, 1e-12) << summary.FullReport();
  EXPECT_EQ(check.matched, static_cast<int>(tones.size()));
  EXPECT_EQ(check.wrong_labels, 0);
}

TEST(FrequencyIdentification, RejectsInvalidInput) {
  Signal signal;
  signal.dt = 0.0;
  signal.samples = Eigen::MatrixXd::Zero(100, 1);
  IdentificationSummary summary;
  EXPECT_FALSE(IdentifyFrequencies(IdentificationOptions(), signal, &summary));
  EXPECT_EQ(summary.status, IdentificationStatus::kInvalidInput);
  EXPECT_NE(summary.message.find("dt"), std::string::npos);

  signal.dt = 0.1;
  IdentificationOptions options;
  options.bases.max_bases = 5;
  EXPECT_FALSE(IdentifyFrequencies(options, signal, &summary));
  EXPECT_EQ(summary.status, IdentificationStatus::kInvalidInput);
}

TEST(FrequencyIdentification, ConstantSignalHasNoComponents) {
  Signal signal;
  signal.dt = 0.1;
  signal.samples = Eigen::MatrixXd::Constant(1000, 1, 2.5);
  IdentificationSummary summary;
  EXPECT_FALSE(IdentifyFrequencies(IdentificationOptions(), signal, &summary));
  EXPECT_EQ(summary.status, IdentificationStatus::kNoComponents);
  EXPECT_NEAR(summary.mean(0), 2.5, 1e-12);
}

// A settled MEMS record (SI units) whose integration noise made detection
// add a line, polish pull it off its peak and prune it, and the peak come
// back: the loop never ended (a user's `solve` hung). The rounds are now
// bounded: the identification ends, usable, on the known base.
TEST(FrequencyIdentification, ALineThatKeepsComingBackEndsTheDetection) {
  std::ifstream in("tests/frequency_id/data/mems-cycling-record.txt");
  ASSERT_TRUE(in) << "run from the source root";
  std::string line;
  while (std::getline(in, line) && line[0] == '#') {
  }
  Signal signal;
  std::istringstream(line) >> signal.t0 >> signal.dt;
  std::vector<double> x;
  for (double v; in >> v;) x.push_back(v);
  ASSERT_EQ(x.size(), 4133u);
  signal.samples = Eigen::Map<const Eigen::MatrixXd>(x.data(), static_cast<long>(x.size()), 1);
  IdentificationOptions options;  // as the analyze pipeline (rmhb/pipeline/analyze.cc)
  options.relative_threshold = 1e-8;
  options.max_components = 32;
  options.bases.max_bases = 1;
  options.bases.known_frequencies = {1.05e5};
  IdentificationSummary s;
  IdentifyFrequencies(options, signal, &s);
  EXPECT_NE(s.message.find("kept coming back"), std::string::npos) << s.message;
  EXPECT_LE(s.num_polishes, 4 * 32);
  ASSERT_TRUE(s.IsUsable()) << s.message;
  ASSERT_EQ(s.bases.size(), 1u);
  EXPECT_EQ(s.bases[0].frequency, 1.05e5);
  ASSERT_FALSE(s.components.empty());
  EXPECT_NEAR(s.components[0].frequency, 1.05e5, 1e-9 * 1.05e5);  // the drive, to the record's precision
}

}  // namespace
}  // namespace rmhb::frequency_id

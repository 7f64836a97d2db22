#ifndef RMHB_TESTS_FREQUENCY_ID_SYNTHETIC_SIGNAL_H_
#define RMHB_TESTS_FREQUENCY_ID_SYNTHETIC_SIGNAL_H_

#include <cmath>
#include <random>
#include <vector>

#include "frequency_id/signal.h"

namespace rmhb::frequency_id::testing {

// Two close base frequencies (0.0079 apart: 16 bins for T = 12800), the
// asymmetric pendulum's kind of spectrum.
inline constexpr double kW1 = 0.9857123456789;
inline constexpr double kW2 = 0.9935987654321;

// One line of a synthetic record: frequency label . bases, and per channel
// amplitude * gain[c] cos(omega t + phase + c * 0.3).
struct Tone {
  std::vector<int> label;
  double amplitude = 1.0;
  double phase = 0.0;
};

inline double ToneFrequency(const std::vector<double>& bases, const std::vector<int>& label) {
  double f = 0.0;
  for (std::size_t i = 0; i < label.size(); ++i) f += label[i] * bases[i];
  return f;
}

// Channel c of the record scales every tone by gains[c] and shifts its phase
// by 0.3 c; white Gaussian noise of std noise_std (fixed seed) is added.
inline Signal MakeSignal(const std::vector<double>& bases, const std::vector<Tone>& tones,
                         double dt, int size, double t0 = 0.0,
                         const std::vector<double>& gains = {1.0}, double noise_std = 0.0,
                         unsigned seed = 12345, double mean = 0.0) {
  Signal signal;
  signal.dt = dt;
  signal.t0 = t0;
  signal.samples = Eigen::MatrixXd::Constant(size, static_cast<int>(gains.size()), mean);
  for (const Tone& tone : tones) {
    const double omega = ToneFrequency(bases, tone.label);
    for (std::size_t c = 0; c < gains.size(); ++c) {
      for (int n = 0; n < size; ++n) {
        const double t = t0 + n * dt;
        signal.samples(n, static_cast<int>(c)) +=
            gains[c] * tone.amplitude * std::cos(omega * t + tone.phase + 0.3 * c);
      }
    }
  }
  if (noise_std > 0.0) {
    std::mt19937_64 generator(seed);
    std::normal_distribution<double> normal(0.0, noise_std);
    for (Eigen::Index c = 0; c < signal.samples.cols(); ++c) {
      for (int n = 0; n < size; ++n) signal.samples(n, c) += normal(generator);
    }
  }
  return signal;
}

}  // namespace rmhb::frequency_id::testing

#endif  // RMHB_TESTS_FREQUENCY_ID_SYNTHETIC_SIGNAL_H_

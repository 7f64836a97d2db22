#ifndef RMHB_FREQUENCY_ID_SPECTRUM_H_
#define RMHB_FREQUENCY_ID_SPECTRUM_H_

#include <limits>
#include <vector>

#include <Eigen/Core>

#include "frequency_id/sample_grid.h"
#include "frequency_id/window.h"

namespace rmhb::frequency_id {

// A local maximum of the windowed amplitude spectrum.
struct SpectralPeak {
  int bin = 0;
  double frequency = 0.0;  // bin * BinWidth(), rad per unit time
  double amplitude = 0.0;  // line amplitude estimate at that bin
};

struct PeakSearchOptions {
  double min_frequency = 0.0;
  double max_frequency = std::numeric_limits<double>::infinity();
  double min_amplitude = 0.0;
  int max_peaks = std::numeric_limits<int>::max();
};

// Windowed amplitude spectrum of a multichannel record on the DFT grid,
// through FFTW's real-to-complex transform. The plan and its buffers are made
// once per analyzer and reused for every channel and every call, since the
// detection loop transforms the residual once per detected line.
//
// The spectrum is summed over channels so that a line is found once however
// many channels carry it:
//
//   A(k) = 2 sqrt( sum_c |sum_n w_n x_nc e^{-2 pi i k n / N}|^2 ) / sum_n w_n,
//
// so a line a cos(omega t + phase) sitting exactly on a bin reads A = |a|
// (the Euclidean norm of the per-channel amplitudes for several channels).
//
// Not thread-safe (one analyzer per thread); constructing analyzers from
// several threads is safe.
class SpectrumAnalyzer {
 public:
  SpectrumAnalyzer(const SampleGrid& grid, const Window& window);
  ~SpectrumAnalyzer();
  SpectrumAnalyzer(const SpectrumAnalyzer&) = delete;
  SpectrumAnalyzer& operator=(const SpectrumAnalyzer&) = delete;

  // `samples` has grid.size rows and any number of columns.
  const Eigen::VectorXd& Compute(const Eigen::MatrixXd& samples);
  const Eigen::VectorXd& amplitudes() const { return amplitudes_; }

  int num_bins() const { return static_cast<int>(amplitudes_.size()); }
  double BinFrequency(int bin) const { return bin * grid_.BinWidth(); }
  const SampleGrid& grid() const { return grid_; }
  const Window& window() const { return window_; }
  // The sampled window w_n and its sum (the normalisation of A).
  const Eigen::VectorXd& weights() const { return weights_; }
  double weight_sum() const { return weight_sum_; }

  // Local maxima of the last computed spectrum inside the frequency band and
  // above min_amplitude, strongest first.
  std::vector<SpectralPeak> FindPeaks(const PeakSearchOptions& options) const;

  // Median of A(k) over the bins inside [min_frequency, max_frequency]: a
  // robust level of the noise (or of the round-off) floor, unaffected by the
  // few bins that hold lines.
  double MedianAmplitude(double min_frequency, double max_frequency) const;

 private:
  SampleGrid grid_;
  Window window_;
  Eigen::VectorXd weights_;
  double weight_sum_ = 0.0;
  Eigen::VectorXd amplitudes_;
  double* input_ = nullptr;
  void* output_ = nullptr;  // fftw_complex*, kept opaque to spare users fftw3.h
  void* plan_ = nullptr;    // fftw_plan
};

}  // namespace rmhb::frequency_id

#endif  // RMHB_FREQUENCY_ID_SPECTRUM_H_

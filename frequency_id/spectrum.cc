#include "frequency_id/spectrum.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <new>
#include <stdexcept>

namespace rmhb::frequency_id {
namespace {

// FFTW's planner keeps global state: only fftw_execute is thread-safe.
std::mutex& PlannerMutex() {
  static std::mutex mutex;
  return mutex;
}

// The bin range [first, last] covering [low, high], clamped to [0, max_bin]
// before any conversion to int (the band may be infinite).
void BinRange(double low, double high, double bin_width, int max_bin, int* first, int* last) {
  const double lo = std::clamp(std::ceil(low / bin_width), 0.0, static_cast<double>(max_bin));
  const double hi = std::clamp(std::floor(high / bin_width), -1.0, static_cast<double>(max_bin));
  *first = static_cast<int>(lo);
  *last = static_cast<int>(hi);
}

}  // namespace

SpectrumAnalyzer::SpectrumAnalyzer(const SampleGrid& grid, const Window& window)
    : grid_(grid), window_(window) {
  if (grid.size < 4) throw std::invalid_argument("SpectrumAnalyzer: need at least 4 samples");
  weights_ = window_.Sample(grid.size);
  weight_sum_ = weights_.sum();
  amplitudes_ = Eigen::VectorXd::Zero(grid.size / 2 + 1);
  input_ = static_cast<double*>(fftw_malloc(sizeof(double) * grid.size));
  output_ = fftw_malloc(sizeof(fftw_complex) * (grid.size / 2 + 1));
  if (input_ == nullptr || output_ == nullptr) {
    fftw_free(input_);
    fftw_free(output_);
    throw std::bad_alloc();
  }
  std::lock_guard<std::mutex> lock(PlannerMutex());
  // FFTW_ESTIMATE: planning must stay cheap next to a single transform, and
  // it leaves the input untouched.
  plan_ = fftw_plan_dft_r2c_1d(grid.size, input_, static_cast<fftw_complex*>(output_),
                               FFTW_ESTIMATE);
  if (plan_ == nullptr) {
    fftw_free(input_);
    fftw_free(output_);
    throw std::runtime_error("SpectrumAnalyzer: FFTW could not make a plan");
  }
}

SpectrumAnalyzer::~SpectrumAnalyzer() {
  {
    std::lock_guard<std::mutex> lock(PlannerMutex());
    fftw_destroy_plan(static_cast<fftw_plan>(plan_));
  }
  fftw_free(input_);
  fftw_free(output_);
}

const Eigen::VectorXd& SpectrumAnalyzer::Compute(const Eigen::MatrixXd& samples) {
  if (samples.rows() != grid_.size) {
    throw std::invalid_argument("SpectrumAnalyzer::Compute: wrong number of samples");
  }
  const int num_bins = grid_.size / 2 + 1;
  Eigen::VectorXd power = Eigen::VectorXd::Zero(num_bins);
  const auto* out = static_cast<const fftw_complex*>(output_);
  for (Eigen::Index c = 0; c < samples.cols(); ++c) {
    for (int n = 0; n < grid_.size; ++n) input_[n] = weights_(n) * samples(n, c);
    fftw_execute(static_cast<fftw_plan>(plan_));
    for (int k = 0; k < num_bins; ++k) power(k) += out[k][0] * out[k][0] + out[k][1] * out[k][1];
  }
  amplitudes_ = (2.0 / weight_sum_) * power.cwiseSqrt();
  return amplitudes_;
}

std::vector<SpectralPeak> SpectrumAnalyzer::FindPeaks(const PeakSearchOptions& options) const {
  const double bin_width = grid_.BinWidth();
  int first_bin = 0;
  int last_bin = 0;
  BinRange(options.min_frequency, options.max_frequency, bin_width, num_bins() - 1, &first_bin,
           &last_bin);
  // Both neighbours must exist.
  first_bin = std::max(first_bin, 1);
  last_bin = std::min(last_bin, num_bins() - 2);
  std::vector<SpectralPeak> peaks;
  for (int k = first_bin; k <= last_bin; ++k) {
    const double a = amplitudes_(k);
    // Ties go to the left neighbour so a flat top yields one peak.
    if (a > amplitudes_(k - 1) && a >= amplitudes_(k + 1) && a >= options.min_amplitude) {
      peaks.push_back({k, k * bin_width, a});
    }
  }
  std::sort(peaks.begin(), peaks.end(),
            [](const SpectralPeak& a, const SpectralPeak& b) { return a.amplitude > b.amplitude; });
  if (static_cast<int>(peaks.size()) > options.max_peaks) peaks.resize(options.max_peaks);
  return peaks;
}

double SpectrumAnalyzer::MedianAmplitude(double min_frequency, double max_frequency) const {
  int first_bin = 0;
  int last_bin = 0;
  BinRange(min_frequency, max_frequency, grid_.BinWidth(), num_bins() - 1, &first_bin, &last_bin);
  if (last_bin < first_bin) return 0.0;
  std::vector<double> values(amplitudes_.data() + first_bin, amplitudes_.data() + last_bin + 1);
  auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace rmhb::frequency_id

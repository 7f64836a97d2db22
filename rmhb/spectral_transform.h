#ifndef RMHB_SPECTRAL_TRANSFORM_H_
#define RMHB_SPECTRAL_TRANSFORM_H_

// The collocation matrices E (coefficients -> samples) and E* (samples ->
// coefficients, E* E = I) applied through FFTW rather than as dense M x (2K-1)
// products, plus the spectrum of sampled functions that the Jacobian needs:
// multiplying by p(t) and projecting is a Toeplitz-plus-Hankel matrix built
// from p's discrete Fourier coefficients at k - l and k + l.

#include <complex>
#include <vector>

#include <Eigen/Dense>

#include "rmhb/harmonic_basis.h"
#include "rmhb/sampling.h"

namespace rmhb {

class SpectralTransform {
 public:
  // Throws std::invalid_argument if two harmonics of the basis land on the
  // same grid frequency (the grid cannot even represent the basis).
  SpectralTransform(const HarmonicBasis& basis, const Sampling& sampling);
  ~SpectralTransform();
  SpectralTransform(const SpectralTransform&) = delete;
  SpectralTransform& operator=(const SpectralTransform&) = delete;

  long num_samples() const { return total_; }
  int num_coefficients() const { return basis_.num_coefficients(); }

  // samples = E coefficients.
  void Synthesize(const double* coefficients, double* samples);
  // coefficients = E* samples.
  void Project(const double* samples, double* coefficients);
  // Stores the discrete spectrum of `samples` for MultiplicationMatrix.
  void Analyze(const double* samples);
  // out += scale * E* diag(p) E, p the last analysed function. Columns of E
  // may be weighted: column l of E is replaced by the derivative-style
  // combination given by `derivative_rates` when not null (rate[l] = k_l.w):
  // cos -> -rate sin, sin -> rate cos, constant -> 0. This is E* diag(p) E D.
  void AddMultiplicationMatrix(double scale, const double* derivative_rates,
                               Eigen::Ref<Eigen::MatrixXd> out) const;

  // exp(i g.phi_s) phase of sample s for integer grid vector g, as the
  // fraction (g.s mod M)/M per angle; used to sample time functions exactly.
  double Phase(const std::vector<int>& base_harmonic, long sample) const;

 private:
  std::complex<double> SpectrumAt(const int* grid_index) const;
  long HalfIndex(const int* reduced) const;

  HarmonicBasis basis_;
  Sampling sampling_;
  int dims_;
  long total_;
  long half_total_;
  std::vector<int> grid_index_;  // [harmonic][dim], embedded, not reduced
  double* real_ = nullptr;
  std::complex<double>* spectrum_ = nullptr;
  std::vector<std::complex<double>> analysed_;
  void* forward_ = nullptr;   // fftw_plan
  void* backward_ = nullptr;  // fftw_plan
};

}  // namespace rmhb

#endif  // RMHB_SPECTRAL_TRANSFORM_H_

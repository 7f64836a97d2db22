#ifndef RMHB_SPECTRAL_TRANSFORM_H_
#define RMHB_SPECTRAL_TRANSFORM_H_

// The collocation matrices E (coefficients -> samples) and E* (samples ->
// coefficients, E* E = I) applied through FFTs (large grids) or dense
// products with tables (small ones), plus the spectrum of sampled functions that the Jacobian needs:
// multiplying by p(t) and projecting is a Toeplitz-plus-Hankel matrix built
// from p's discrete Fourier coefficients at k - l and k + l.
//
// Two backends, the same results to round-off (tests/rmhb/
// spectral_transform_test.cc compares them):
//  - small one-angle grids (M <= kMaxDenseSamples): dense products with
//    precomputed cos/sin tables, O(M K) per transform and nothing to plan.
//    FFTW's first plan in a process costs 0.4-1 ms (its planner's set-up
//    plus the size's own planning, FFTW_ESTIMATE), more than a whole solve
//    of a small problem (issue 14: the pendulum at N = 25 spent most of its
//    `rmhb solve` time planning); the dense transform of M = 80 samples
//    costs ~1 us, and the tables cost one pass over E (the spectrum's, for
//    the Jacobian, on first use), made once per grid and shared by the
//    transforms of the process (a cache of the most recent 16 grids);
//  - otherwise FFTW, with plans made once per grid and kind per process
//    (a cache shared by all transforms, executed on their own arrays
//    through FFTW's new-array interface): continuation, Monte Carlo and
//    order continuation no longer plan per solve.

#include <complex>
#include <memory>
#include <vector>

#include <Eigen/Dense>

#include "rmhb/harmonic_basis.h"
#include "rmhb/sampling.h"

namespace rmhb {

// Grids of one angle with at most this many samples use the dense backend.
constexpr long kMaxDenseSamples = 384;

class SpectralTransform {
 public:
  enum class Backend { kAuto, kDense, kFftw };
  // Throws std::invalid_argument if two harmonics of the basis land on the
  // same grid frequency (the grid cannot even represent the basis). kDense
  // needs a grid of one angle (else std::invalid_argument).
  SpectralTransform(const HarmonicBasis& basis, const Sampling& sampling,
                    Backend backend = Backend::kAuto);
  ~SpectralTransform();
  SpectralTransform(const SpectralTransform&) = delete;
  SpectralTransform& operator=(const SpectralTransform&) = delete;

  long num_samples() const { return total_; }
  bool dense() const { return dense_; }
  int num_coefficients() const { return basis_.num_coefficients(); }

  // samples = E coefficients.
  void Synthesize(const double* coefficients, double* samples);
  // coefficients = E* samples.
  void Project(const double* samples, double* coefficients);
  // The same for a vector that is zero outside `some` (synthesis), or
  // wanted only at `some` (projection): a symmetry's dropped harmonics. The
  // dense tables skip the rest (the projection leaves the other entries of
  // `coefficients_out` as they were); FFTW transforms everything.
  void SynthesizeSome(const double* coefficients, const std::vector<int>& some, double* samples);
  void ProjectSome(const double* samples, const std::vector<int>& some, double* coefficients_out);
  // Stores the discrete spectrum of `samples` for MultiplicationMatrix.
  // Throws std::logic_error on a shifted grid (Sampling::half_step), which
  // serves residual evaluations only.
  void Analyze(const double* samples);
  // out += scale * E* diag(p) E, p the last analysed function. Columns of E
  // may be weighted: column l of E is replaced by the derivative-style
  // combination given by `derivative_rates` when not null (rate[l] = k_l.w):
  // cos -> -rate sin, sin -> rate cos, constant -> 0. This is E* diag(p) E D.
  // Harmonics whose flag is 0 in `row_harmonics` (rows) or
  // `column_harmonics` (columns), arrays over the basis when not null, are
  // skipped and left as they were in `out`: a Jacobian that a symmetry will
  // reduce needs only the entries it keeps (a quarter under a half-wave one).
  void AddMultiplicationMatrix(double scale, const double* derivative_rates,
                               Eigen::Ref<Eigen::MatrixXd> out,
                               const char* row_harmonics = nullptr,
                               const char* column_harmonics = nullptr) const;
  // The same restricted to the basis harmonics [first, last) (rows and
  // columns both): out is the block of their coefficients, the constant (if
  // first = 0) then cos, sin per harmonic. Sparse Jacobians and their
  // preconditioners (METHOD.md s.17) take the low harmonics' block and the
  // 2 x 2 diagonal blocks of the higher ones without the whole C x C block.
  void AddMultiplicationBlock(double scale, const double* derivative_rates, int first, int last,
                              Eigen::Ref<Eigen::MatrixXd> out, const char* row_harmonics = nullptr,
                              const char* column_harmonics = nullptr) const;

  // Where AddMultiplicationTo puts an entry (row coefficient r, column
  // coefficient c) of E* diag(p) E (D): into out(rows[r], columns[c]); a
  // row or column of -1 is dropped (a Jacobian's reduced rows and columns).
  struct Targets {
    const int* rows = nullptr;
    const int* columns = nullptr;
  };
  // AddMultiplicationMatrix with scale 1, each entry put straight where
  // `targets` says: no C x C block, and only the entries some target keeps
  // are formed (a quarter under a half-wave symmetry with a time reversal).
  // One grid angle only (num_angles() == 1).
  void AddMultiplicationTo(const double* derivative_rates, const Targets& targets,
                           Eigen::Ref<Eigen::MatrixXd> out) const;
  // AddConstantMultiplication the same way.
  void AddConstantMultiplicationTo(double value, const double* derivative_rates, const Targets& targets,
                                   Eigen::Ref<Eigen::MatrixXd> out) const;
  int num_angles() const { return dims_; }

  // out += scale * E* diag(p) E (D) for a constant p = value: value times
  // the identity (or D(rate)), since E* E = I on a grid where every harmonic
  // owns its frequency (the constructor's check). A linear term's partial is
  // constant: O(C) instead of the O(C^2) Toeplitz-plus-Hankel, no Analyze.
  // Exact where AddMultiplicationMatrix carries the round-off of the
  // analysed spectrum.
  void AddConstantMultiplication(double value, const double* derivative_rates,
                                 Eigen::Ref<Eigen::MatrixXd> out) const;

  // exp(i g.phi_s) phase of sample s for integer grid vector g, as the
  // fraction (g.s mod M)/M per angle; used to sample time functions exactly.
  double Phase(const std::vector<int>& base_harmonic, long sample) const;
  // Phase(base_harmonic, s) for every sample s, into phases[0 .. num_samples()).
  void Phases(const std::vector<int>& base_harmonic, double* phases) const;

 private:
  std::complex<double> SpectrumAt(const int* grid_index) const;
  // g.k along angle d for base harmonic k (the embedding's row d).
  long GridRate(const std::vector<int>& base_harmonic, int d) const;
  // One angle: P at the differences and sums of harmonics [first, last)'s
  // grid indices, into line_spectrum_ and sum_spectrum_.
  void GatherLineSpectrum(int first, int last) const;
  // Harmonic l's cos and sin columns of E* diag(p) E, their components at
  // harmonic k: (P[k-l] + P[k+l]) / 2 and -i (P[k-l] - P[k+l]) / 2 (P[k]
  // and 0 for the constant). On one angle it reads what GatherLineSpectrum
  // gathered for a range holding k and l; on several, the spectrum itself.
  struct ProductPair {
    std::complex<double> cos, sin;
  };

  ProductPair ProductAt(int k, int l) const;
  long HalfIndex(const int* reduced) const;
  void SetUpDense();
  void SetUpDenseSpectrum();  // on the first Analyze: residual-only users skip it
  void Fold(const double* samples);      // even_, odd_ on the half grid
  void Unfold(double* samples) const;    // from even_ (cos part) and odd_ (sin part)
  void DenseSums();                      // cos_part_, sin_part_ from even_, odd_
  void ForwardFftw(const double* samples);  // real_ -> spectrum_
  // A shifted grid (Sampling::half_step): each harmonic's phase advance
  // over the half steps, and the coefficients turned by it.
  void SetUpShift(const std::vector<int>& half_step);
  const double* Advance(const double* x, const std::vector<int>* some);
  void TurnBack(double* x) const;
  std::vector<int> BothOfEachHarmonic(const std::vector<int>& some) const;
  // The transforms of the unshifted grid.
  void SynthesizeOnGrid(const double* x, double* samples);
  void SynthesizeSomeOnGrid(const double* x, const std::vector<int>& some, double* samples);
  void ProjectOnGrid(const double* samples, double* x);
  void ProjectSomeOnGrid(const double* samples, const std::vector<int>& some, double* x);

  HarmonicBasis basis_;
  Sampling sampling_;
  int dims_;
  long total_;
  long half_total_;
  std::vector<int> grid_index_;  // [harmonic][dim], embedded, not reduced
  double* real_ = nullptr;
  std::complex<double>* spectrum_ = nullptr;
  std::vector<std::complex<double>> analysed_;
  // One angle: P[g] at the differences g = -span..span and the sums g =
  // low..low + 2 span of the block being built (GatherLineSpectrum).
  mutable std::vector<std::complex<double>> line_spectrum_, sum_spectrum_;
  mutable int line_span_ = 0, line_low_ = 0;
  mutable std::vector<int> active_rows_;  // AddMultiplicationTo's row harmonics
  void* forward_ = nullptr;   // fftw_plan, owned by the process-wide cache
  void* backward_ = nullptr;  // fftw_plan, owned by the process-wide cache
  // Dense backend: E's cos and sin columns on the half grid t = 0 .. M/2
  // (the rest mirrors them; E* is E' scaled), and the rows of the half
  // spectrum beyond the basis's harmonics, shared with every transform of
  // the same grid in the process (made once, read only).
  struct DenseTables;
  struct SpectrumTables;
  bool dense_ = false;
  std::shared_ptr<const DenseTables> dense_tables_;
  std::shared_ptr<const SpectrumTables> spectrum_tables_;
  Eigen::VectorXd even_, odd_, cos_part_, sin_part_;  // half-grid samples, per-harmonic sums
  Eigen::VectorXd half_re_, half_im_;
  std::vector<int> half_step_;                     // empty: not shifted
  std::vector<double> advance_cos_, advance_sin_;  // per basis harmonic
  Eigen::VectorXd turned_, projected_;
};

}  // namespace rmhb

#endif  // RMHB_SPECTRAL_TRANSFORM_H_

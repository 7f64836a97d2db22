#ifndef RMHB_SAMPLING_H_
#define RMHB_SAMPLING_H_

// Where the collocation points lie. All harmonic balance variants are one
// collocation framework that differs only in the number of samples M
// (METHOD.md s.3): HDHB uses M = 2N+1 (aliases), RHB the smallest alias-free
// M > (phi+1)N (Theorem 1), HB-AFT a power of two >= 2 phi N + 1.
//
// A sampling is a uniform grid over a torus of `grid.size()` angles phi_g in
// [0, 2 pi). Base frequency i moves angle g at the integer rate
// embedding[g][i], so the time function of harmonic k is exp(i (E k).phi).
//  - periodic: one angle, E = [1];
//  - torus (quasi-periodic, default): one angle per base, E = identity;
//  - GCD rule (Theorem 2): one angle over T = 2 pi / gcd(w), E = [r_1 ... r_d]
//    with w_i = r_i gcd.

#include <string>
#include <vector>

#include "rmhb/harmonic_basis.h"
#include "rmhb/polynomial_system.h"

namespace rmhb {

enum class SamplingRule {
  kRhb,   // smallest alias-free count, rounded up to an FFT-friendly size
  kHdhb,  // 2N+1 per dimension: Hall's high-dimensional HB, aliases
  kAft,   // power of two >= 2 phi N + 1: classical alternating frequency-time
};

const char* ToString(SamplingRule rule);
// Parses "rhb", "hdhb", "aft"; throws std::invalid_argument otherwise.
SamplingRule ParseSamplingRule(const std::string& name);

struct Sampling {
  std::vector<int> grid;                    // points per torus angle
  std::vector<std::vector<int>> embedding;  // [grid angle][base]
  std::string description;
  // Per grid angle, 1: the samples sit half a step on, at (j + 1/2) 2 pi / M
  // (empty or 0: at j 2 pi / M). A grid and its shifted copies together are
  // the grid twice as fine, through the grid's own tables and plans
  // (SpectralTransform): the alias check of pointwise equations.
  std::vector<int> half_step;

  long total() const;
  static Sampling Uniform(int samples);
  static Sampling Torus(const std::vector<int>& samples);
  static Sampling Gcd(int samples, const std::vector<int>& ratios);
};

// Theorem 2 (GCD rule): w_i ~= r_i g with small integers r_i, from continued
// fractions of w_i / w_1 within `tolerance` (relative). Throws
// std::invalid_argument, saying why, when no such ratios exist with
// denominators up to `max_ratio` (irrational-looking or too close).
std::vector<int> RationalRatios(const std::vector<double>& frequencies, double tolerance,
                                long max_ratio);

// Smallest n >= m whose prime factors are 2, 3, 5, 7 (fast FFTW sizes).
int FftFriendlySize(int m);

// Samples along each base for `rule` on this system and basis; the per-base
// alias-free minimum is written to `alias_free` when given. A system with
// pointwise equations (PolynomialSystem::HasPointwise) has no alias-free
// count (0 is written): rhb then takes M >= kPointwiseOversampling reach + 1
// (the harmonics that fold onto the kept ones are those beyond M - N >= 2N,
// the square of the truncated tail for a geometrically decaying spectrum),
// aft the power of two >= 4 reach + 1 (NLvib's rule), hdhb 2 reach + 1.
// A piecewise-smooth pointwise equation (PolynomialSystem::HasNonSmooth)
// takes the power of two >= kNonSmoothOversampling reach + 1 and at least the
// polynomial equations' alias-free count, whatever the rule but hdhb: its
// spectrum decays algebraically (a kink: |c_k| ~ k^-2), so the folded part
// falls only like M^-2 (METHOD.md s.15, the measured rates in the README).
// The polynomial equations stay exact on any grid above their alias-free
// count (Theorem 1), so they keep RHB's treatment on the finer grid.
constexpr int kPointwiseOversampling = 3;
constexpr int kNonSmoothOversampling = 128;
// The grid of a non-smooth system for `reach` harmonics with the given
// oversampling (NonSmoothSamples(21) = 4096; NLvib's example 03 uses 1024).
int NonSmoothSamples(int reach, int oversampling = kNonSmoothOversampling, int alias_free = 0);
std::vector<int> SamplesForRule(const PolynomialSystem& system, const HarmonicBasis& basis,
                                SamplingRule rule, std::vector<int>* alias_free = nullptr);

}  // namespace rmhb

#endif  // RMHB_SAMPLING_H_

#ifndef RMHB_TRUNCATION_ESTIMATE_H_
#define RMHB_TRUNCATION_ESTIMATE_H_

// How far a harmonic balance solution on a truncated basis is from the
// untruncated one, per quantity (METHOD.md s.8):
//   TruncationEstimate e = EstimateTruncation(solution, &lower_order_solution);
//   e.state      // max over variables of the time-domain error, relative to the variable
//   e.frequency  // relative error of the unknown base frequencies
// From the coefficient tail: the sizes of the harmonics on the basis's outer
// boundary (each variable relative to its largest coefficient), times the
// geometric factor of the decay fitted along the levels |k|_1. The error of
// the retained coefficients is the tail times a problem constant (the
// Jacobian's amplification: near a resonance more than 1); a solution of the
// same problem on a smaller basis measures that constant per quantity (their
// difference against the smaller basis's tail), so the frequency's faster
// convergence (Van der Pol: its error ~ the tail squared) is stated
// separately. Without one the constant is taken as 1.
// A model with kinks or jumps (PolynomialSystem::HasNonSmooth) decays
// algebraically, sizes ~ l^-p: its tail and prediction follow that law
// (DecayModel::kAlgebraic; METHOD.md s.15), where a geometric fit would
// under-report the neglected harmonics (1.3e-4 estimated, 5.9e-4 measured on
// NLvib's example 03 at N = 100).

#include <vector>

#include "rmhb/harmonic_solution.h"

namespace rmhb {

enum class DecayModel { kGeometric, kAlgebraic };
// Kinks and jumps (PolynomialSystem::HasNonSmooth) decay algebraically.
inline DecayModel DecayFor(const PolynomialSystem& system) {
  return system.HasNonSmooth() ? DecayModel::kAlgebraic : DecayModel::kGeometric;
}

struct TruncationEstimate {
  DecayModel model = DecayModel::kGeometric;
  double tail = 0;        // boundary sizes times the decay factor (relative)
  double decay = 1;       // geometric: fitted ratio of sizes per level; 1 when no decay is seen
  double exponent = 0;    // algebraic: fitted p of sizes ~ l^-p; 0 when no decay is seen
  int top_level = 0;      // largest |k|_1 in the basis
  double state = 0;       // estimated max time-domain error, relative per variable
  double frequency = 0;   // estimated relative error of the frequencies (unknown ones)
  bool calibrated = false;  // the constants came from a lower-order solution
  // The smallest top level whose predicted state error is below `target`
  // (extrapolating the decay); top_level when met, -1 when no decay is seen.
  int PredictLevel(double target) const;
};

// The band around the unit circle within which a stability verdict says
// neutral: `band`, widened to kMultiplierErrorPerTruncation times the
// orbit's estimated error (EstimateTruncation(s).state) when that is
// larger, *widened (may be null) set then. Multipliers computed from an
// orbit that is e off are not known to better than ~e: the relativistic
// oscillator at N = 80, beta = 0.98 (5.9e-6 off by its tail) gave 1.0000095
// beside the deflated trivial 1, where an exact orbit has a double 1.
constexpr double kMultiplierErrorPerTruncation = 10;
double NeutralBand(const HarmonicSolution& s, double band, bool* widened = nullptr);

// `lower`: the same problem solved on a basis contained in s.basis() (may be
// null). Frequency errors count only the frequencies that differ between
// the two; without `lower` the frequency estimate is the state estimate.
TruncationEstimate EstimateTruncation(const HarmonicSolution& s, const HarmonicSolution* lower = nullptr,
                                      DecayModel model = DecayModel::kGeometric);

// How far `other` is from s in the estimate's measure of the state: per
// variable relative to its largest coefficient in s, the sum of the
// coefficients' differences on s.basis() (a bound on the time-domain
// difference), or for kAlgebraic on one base the time-domain difference
// itself (sampled, 8 points per harmonic: the sum would count a coarser
// solution's missing harmonics whole, several times the difference).
double StateDifference(const HarmonicSolution& s, const HarmonicSolution& other,
                       DecayModel model = DecayModel::kGeometric);

// max over the base frequencies of |w_other - w_s| / |w_s|.
double FrequencyDifference(const HarmonicSolution& s, const HarmonicSolution& other);

// Per harmonic k of s.basis(): max over variables of |c_jk| / scale_j
// (scale_j: the variable's largest coefficient, at least 1e-6 of the largest
// over all variables), harmonic 0 included.
std::vector<double> HarmonicSizes(const HarmonicSolution& s);

// The steps from a harmonic to its neighbours in d bases: +-1 and +-2 along
// each base and +-1 along two bases at once (|step|_1 <= 2), so that a
// spectrum with only every other harmonic (a half-wave symmetry) still
// connects. The truncation's boundary and the adaptive index set's
// enrichment look at the same neighbours.
std::vector<std::vector<int>> NeighbourSteps(int d);

}  // namespace rmhb

#endif  // RMHB_TRUNCATION_ESTIMATE_H_

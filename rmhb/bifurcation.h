#ifndef RMHB_BIFURCATION_H_
#define RMHB_BIFURCATION_H_

// Codimension-one bifurcations of a branch of periodic orbits, read from
// the Floquet multipliers mu of its points (METHOD.md s.14; Kuznetsov,
// "Elements of Applied Bifurcation Theory", ch. 7; Seydel, "Practical
// Bifurcation and Stability Analysis", ch. 7):
//  - a real multiplier through +1: a fold (turning point) when the branch
//    turns back in the parameter, else a branch point (pitchfork or
//    transcritical, e.g. a symmetric orbit losing its symmetry);
//  - a real multiplier through -1: period doubling (a branch of period 2T
//    is born);
//  - a complex pair through the unit circle: Neimark-Sacker (a torus, a
//    quasi-periodic response with a second frequency, is born).
// Between two points each is detected by the sign of a test function over
// the non-trivial multipliers (the trivial 1 of an autonomous orbit left
// out), as AUTO and MatCont do for limit cycles:
//   psi_+ = prod (mu_i - 1),  psi_- = prod (mu_i + 1),
//   psi_NS = prod_{i<j} (mu_i mu_j - 1).
// A conjugate pair contributes |mu - 1|^2 > 0 to psi_+ and psi_-, so only a
// real multiplier crossing +1 or -1 changes their sign; psi_NS changes sign
// when a complex pair crosses |mu| = 1, and also when two real multipliers
// pass mu_i mu_j = 1 (a "neutral saddle", no bifurcation), which the
// location rejects: the located critical pair must be complex. Only the
// signs are computed (counts of negative real factors), so hundreds of
// multipliers neither overflow nor underflow. A multiplier counts as real
// when |Im mu| <= real_tolerance (1 + |mu|): eigensolvers return real
// eigenvalues of a real matrix with Im exactly 0, and Hill's method puts a
// real negative multiplier at exp((a + i w/2) T), Im ~ 1e-11 |mu|.

#include <cmath>
#include <complex>
#include <limits>
#include <string>
#include <vector>

namespace rmhb {

enum class BifurcationType { kFold, kBranchPoint, kPeriodDoubling, kNeimarkSacker };
// "fold", "branch_point", "period_doubling", "neimark_sacker"
const char* ToString(BifurcationType type);
// "fold", "BP", "PD", "NS": the plot's and the table's marks.
const char* ShortName(BifurcationType type);

using Multipliers = std::vector<std::complex<double>>;

// The Floquet multipliers along a periodic solution: the eigenvalues of the
// monodromy matrix of an integration over one period of the solution, of
// the original equations (ContinuationProblem::monodromy, rmhb/continuation.h;
// rmhb/pipeline/branch.h binds CVODE, or IDA for a DAE) or of the harmonic
// balance linearisation (rmhb/harmonic_monodromy.h). `period_multiple`: the solution's period in periods of the
// problem's own base frequency (2 on a period-doubled branch, whose
// solution has base w/2 while the forcing keeps w).
struct MonodromyResult {
  bool ok = false;
  std::string message;  // why not (no original equations, a failed integration)
  Multipliers multipliers;
  int trivial = -1;     // the phase multiplier of an autonomous orbit, or -1
  std::string integrator;
  double seconds = 0;
};

struct TestFunctionSigns {
  int plus = 1;   // sign of psi_+ (real multiplier through +1)
  int minus = 1;  // sign of psi_- (through -1)
  int torus = 1;  // sign of psi_NS (complex pair through the unit circle)
  // psi_NS's factor from the complex pairs alone: (-1)^(pairs inside the
  // circle). psi_NS also changes sign where two real multipliers' product
  // passes 1 (a neutral saddle); this factor only where a pair crosses.
  int pairs = 1;
};

constexpr double kRealMultiplierTolerance = 1e-8;

// `trivial`: the index of the trivial multiplier, or -1.
TestFunctionSigns TestSigns(const Multipliers& mu, int trivial);

// The modulus a stability verdict judges: the largest non-trivial |mu|
// (`trivial`: its index, or -1). An orbit in a family (every orbit of a
// conservative system; a fold) has a double multiplier at 1 with a Jordan
// block, and an error e in the orbit splits it into 1 +- sqrt(e) while their
// product stays 1 + O(e): the relativistic oscillator at N = 80, beta =
// 0.975 gave 1.0000015 and 0.9999985 from a 4e-7 truncation. So when the
// real multiplier nearest the trivial one makes a product with it within
// `band` of 1, the pair counts by its geometric mean (*paired set to true):
// the verdict of such a pair is neutral, as the exact multipliers say.
double JudgedModulus(const Multipliers& mu, int trivial, double band, bool* paired = nullptr);

// The multiplier that crosses for `type` and its signed distance from the
// crossing: the real one nearest +1 (fold, branch point; mu - 1), the real
// one nearest -1 (period doubling; mu + 1), the complex one (Im > 0) nearest
// the unit circle (Neimark-Sacker; |mu| - 1). false when there is none of
// that kind.
bool CriticalMultiplier(const Multipliers& mu, int trivial, BifurcationType type, std::complex<double>* critical,
                        double* distance);

// A located bifurcation of a branch (rmhb/continuation.h).
struct BifurcationPoint {
  BifurcationType type = BifurcationType::kFold;
  double parameter = 0;
  int point = -1;  // its index in ContinuationSummary::points
  // Folds: the tangent's d lambda/ds there. The others: the critical
  // multiplier (for Neimark-Sacker the one with Im > 0) and its signed
  // distance from the crossing (mu - 1, mu + 1, |mu| - 1).
  std::complex<double> multiplier = 0;
  double distance = 0;
  // How well the location converged: |distance| <= tolerance, or the
  // bracket on the arclength could not shrink further. parameter_bracket is
  // the width in the parameter of the last bracket around the crossing
  // (0 when it was met on the first trial).
  bool located = false;
  double tolerance = 0;
  double parameter_bracket = 0;
  // |distance| over the slope d(distance)/d(parameter) across that bracket:
  // the estimated error of `parameter` (NaN when there was no bracket).
  double parameter_error = std::numeric_limits<double>::quiet_NaN();
  int iterations = 0;
  std::string method;  // "hill", "monodromy" or "tangent" (folds)
  // Neimark-Sacker: the new frequency the torus starts with,
  // w2 = w arg(mu) / (2 pi) in (0, w / 2), w the orbit's base frequency.
  double torus_frequency = 0;

  std::string Describe(const std::string& parameter_name) const;  // one line
  // Not located although the bracket shrank to round-off: the multipliers
  // jump across the critical value (a non-smooth orbit grazing a switch);
  // there is no smooth crossing, nor a torus to switch to.
  bool Jump() const {
    return type != BifurcationType::kFold && !located && parameter_bracket <= 1e-12 * (1 + std::abs(parameter));
  }
};

}  // namespace rmhb

#endif  // RMHB_BIFURCATION_H_

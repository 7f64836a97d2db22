#ifndef RMHB_HILL_STABILITY_H_
#define RMHB_HILL_STABILITY_H_

// Stability of a periodic harmonic balance solution by Hill's method: a
// perturbation e^{lambda t} p(t), p periodic, of the steady state z(t)
// satisfies  (A + B D(w)) p^ + lambda B p^ = 0  on the harmonic coefficients,
// with A = E* diag(dg/dz) E and B = E* diag(dg/dz') E the linearisation of the
// equations (CollocationResidual::LinearizationParts). Its generalised
// eigenvalues are the Floquet exponents, each repeated as lambda + i m w for
// every harmonic m the truncation can hold. Only copies whose eigenvector is
// concentrated on the central harmonics are accurate (the others are cut off
// by the truncation), so the selection keeps, per differential state, the
// eigenvalue whose eigenvector's harmonic centroid is closest to zero
// (Lazarus & Thomas, C. R. Mecanique 338, 2010). The multipliers exp(lambda T)
// do not depend on which copy is kept, which is what makes them comparable
// with the monodromy matrix of an integration (integrators/floquet.h).
//
// Large sizes (METHOD.md s.17): the dense QZ costs O((nC)^3) (17 minutes
// for 80 states at N = 25), so above HillOptions::dense_limit rows the
// exponents nearest the imaginary axis come from shift-invert Arnoldi
// (Spectra) on the sparse Hill matrices, factorised by UMFPACK: the
// eigenvalues of (J + sigma B)^-1 (-B) of largest modulus are the lambda
// nearest sigma (a small real shift), i.e. the central copies, found until
// one per differential state survives the same centroid selection.
//
// Tori (METHOD.md s.18): a perturbation e^{lambda t} p(theta), p on the
// torus, gives the same problem on the torus' harmonics, D(w) with the rates
// k.w; each exponent is repeated as lambda + i k.w for every harmonic k of
// the index set, and the central copy is the one whose eigenvector's
// harmonic centroid (a vector, one component per base) is shortest. The
// real parts are the torus' Lyapunov exponents (the linearisation is then
// reducible, as for a periodic orbit by Floquet's theorem); there are no
// multipliers (no period).
//
// Scope: solutions of systems whose equations all balance their constant term. A recast auxiliary pinned at t = 0
// (s' = c v for s = sin(theta)) carries a free constant of integration, which
// would add a spurious neutral exponent; such systems are refused, use the
// Floquet multipliers of the original equations instead.

#include <complex>
#include <string>
#include <vector>

#include "rmhb/collocation_residual.h"
#include "rmhb/harmonic_solution.h"

namespace rmhb {

enum class HillEigensolver { kAuto, kDense, kShiftInvert };
const char* ToString(HillEigensolver eigensolver);  // "auto", "dense", "shift-invert"

struct HillOptions {
  // |Re lambda| below margin * w is neither growth nor decay that a
  // truncated, round-off limited eigenproblem can tell apart: not stable.
  double margin = 1e-9;
  // kAuto: the dense QZ up to dense_limit rows of the Hill matrix (states x
  // coefficients), shift-invert above.
  HillEigensolver eigensolver = HillEigensolver::kAuto;
  int dense_limit = 600;
};

struct HillStabilityReport {
  // Selected Floquet exponents, one per differential state, by decreasing
  // real part; the trivial exponents (closest to 0: the phase shift along
  // an autonomous orbit, one per unknown base of a torus) are listed but
  // excluded from the verdict.
  std::vector<std::complex<double>> exponents;
  std::vector<std::complex<double>> multipliers;  // exp(lambda T), same order; none for a torus
  std::vector<int> trivials;                       // indices of the trivial exponents
  int trivial = -1;                                // the first of them, or -1
  double max_real_part = 0;                        // over non-trivial exponents
  bool stable = false;                             // every non-trivial Re lambda < -margin w_min
  int bases = 1;                                   // of the solution: 2 or more for a torus
  int eigenvalues = 0;                             // finite eigenvalues of the Hill problem computed
  HillEigensolver eigensolver = HillEigensolver::kDense;  // the one used
  int size = 0;                                    // rows of the Hill matrix
  int order = 0;
  double seconds = 0;

  std::string BriefReport() const;
};

// Throws std::invalid_argument for a system with a pinned (constant-free)
// equation, or a solution on the wrong variables or bases.
HillStabilityReport HillStability(const HarmonicBalanceProblem& problem,
                                  const HarmonicSolution& solution, const HillOptions& options = {});

}  // namespace rmhb

#endif  // RMHB_HILL_STABILITY_H_

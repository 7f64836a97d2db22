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
// Scope: periodic solutions (one base frequency) of systems whose equations
// all balance their constant term. A recast auxiliary pinned at t = 0
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
  // real part; for an autonomous solution (unknown frequency) the trivial
  // exponent (closest to 0: the phase shift along the orbit) is listed but
  // excluded from the verdict.
  std::vector<std::complex<double>> exponents;
  std::vector<std::complex<double>> multipliers;  // exp(lambda T), same order
  int trivial = -1;                                // index of the trivial exponent, or -1
  double max_real_part = 0;                        // over non-trivial exponents
  bool stable = false;                             // every non-trivial Re lambda < -margin w
  int eigenvalues = 0;                             // finite eigenvalues of the Hill problem computed
  HillEigensolver eigensolver = HillEigensolver::kDense;  // the one used
  int size = 0;                                    // rows of the Hill matrix
  int order = 0;
  double seconds = 0;

  std::string BriefReport() const;
};

// Throws std::invalid_argument for a quasi-periodic solution, a system with a
// pinned (constant-free) equation, or a solution on the wrong variables.
HillStabilityReport HillStability(const HarmonicBalanceProblem& problem,
                                  const HarmonicSolution& solution, const HillOptions& options = {});

}  // namespace rmhb

#endif  // RMHB_HILL_STABILITY_H_

#ifndef RMHB_DEFINITION_CHECK_H_
#define RMHB_DEFINITION_CHECK_H_

// Is a converged harmonic balance solution a solution of the ORIGINAL
// equations, or only of the polynomial recast at the collocation points?
//
//   DefinitionCheck c = CheckDefinitions(solution, problem.definitions, samples, {});
//   if (!c.physical) ...  // c.Report() says which variable, where, how far
//
// Two silent failures are caught this way (issue 6):
//  - a recast equation has other roots than the auxiliary's definition:
//    u^2 + v^2 - 1 = 0 holds for u = -sqrt(1 - v^2) as well as for the
//    intended u = +sqrt(1 - v^2) (relativistic oscillator, beta = 0.99);
//  - aliasing (HDHB below Theorem 1's bound) makes solutions that satisfy the
//    collocation equations at the samples only.
// Each auxiliary is recomputed from its definition on the solved user
// variables (and their time derivatives), on a grid `oversampling` times
// denser than the collocation grid and shifted by half a step so that no
// point is a collocation point, and compared with its solved value.
//
// Tolerance, tied to the truncation: a truncated Fourier series meets its
// definition between the samples only to about the size of the harmonics it
// leaves out, and those are estimated by the largest harmonic in the top
// quarter of the basis's levels (`tail`, relative to the variable's scale).
// The tolerance is max(floor, truncation_factor * tail), capped at `ceiling`:
// a well-resolved physical solution sits orders of magnitude below it
// (relativistic beta = 0.85, N = 35: ~1e-10 against a floor of 1e-6), a
// wrong root or an alias is O(1) off.

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "rmhb/harmonic_solution.h"

namespace rmhb {

// Every variable of the system from its definition, at torus angles theta,
// given the solved values there: z[j] holds the j-th time derivative of every
// variable (j = 0 .. derivatives). States are read back unchanged;
// auxiliaries are recomputed (sin(theta), 1/R, sqrt(1 - v^2), ...).
struct VariableDefinitions {
  int derivatives = 0;
  std::function<Eigen::VectorXd(const std::vector<double>& theta,
                                const std::vector<Eigen::VectorXd>& z)>
      evaluate;
  explicit operator bool() const { return static_cast<bool>(evaluate); }
};

struct DefinitionCheckOptions {
  int oversampling = 4;            // check grid per base, times the collocation samples
  double floor = 1e-6;             // relative; tolerance never below it
  double truncation_factor = 1e3;  // times the relative tail of the spectrum
  double ceiling = 0.1;            // tolerance never above it
  std::string IsValid() const;     // empty when valid
};

struct DefinitionCheck {
  bool physical = true;
  // Largest |solved - definition| over the grid and the variables, each
  // relative to its variable's scale (max |definition| over the grid, at
  // least 1e-12 so that a vanishing variable is compared absolutely).
  double error = 0;
  std::string worst_variable;       // where it is largest
  std::vector<double> worst_angles;  // torus angles there
  double worst_time = 0;            // the time there (periodic: theta / w)
  double tolerance = 0;
  double tail = 0;                  // relative size of the top quarter of harmonics
  long points = 0;                  // of the check grid
  // Non-finite definitions (a solved value outside a definition's domain,
  // e.g. |v| > 1 under sqrt(1 - v^2)) count as an infinite error there.
  double seconds = 0;
  // One line: "max |solved - definition| 3.3e-01 (relative) in u at t = 15.3
  // > tolerance 0.1 on 1296 points between the samples".
  std::string Report() const;
};

// `collocation_samples`: the samples per base the solve used (the summary's
// `samples`); the check grid is FftFriendlySize(oversampling * M) per base.
// Throws std::invalid_argument for invalid options or a definitions function
// that returns the wrong number of values.
DefinitionCheck CheckDefinitions(const HarmonicSolution& solution,
                                 const VariableDefinitions& definitions,
                                 const std::vector<int>& collocation_samples,
                                 const DefinitionCheckOptions& options = {});

// The same solution differentiated in time `times` times (cos -> -k.w sin ...).
HarmonicSolution TimeDerivative(const HarmonicSolution& solution, int times = 1);

}  // namespace rmhb

#endif  // RMHB_DEFINITION_CHECK_H_

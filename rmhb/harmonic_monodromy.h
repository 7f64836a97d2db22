#ifndef RMHB_HARMONIC_MONODROMY_H_
#define RMHB_HARMONIC_MONODROMY_H_

// The Floquet multipliers of a periodic harmonic balance solution z(t) from
// the monodromy matrix of the equations linearised about z(t) itself,
//   B(t) y' + A(t) y = 0,   A = dg/dz, B = dg/dz'  (n x n, exact at the samples),
// integrated over one period in the time domain (METHOD.md s.16): the
// trapezoidal rule on a uniform grid of the period, whose global error
// expands in even powers of the step, extrapolated (Romberg) over four
// halvings of the step to order 8. Its cost depends on the number of states
// and on the period times the largest rate |B^-1 A|, not on the harmonic
// order: tens of microseconds for a forced one-degree-of-freedom oscillator
// at any N, where Hill's QZ on 62 unknowns (N = 15) takes milliseconds and
// the CVODE monodromy of the original equations about one. The multipliers
// are those of the harmonic balance's own linearisation, like Hill's: both
// converge to the true ones with the harmonic balance's truncation error
// (compared with Hill and with CVODE in tests/rmhb/harmonic_monodromy_test.cc).
//
// Applies to periodic solutions of square first-order systems without recast
// auxiliaries (every variable a state) whose B(t) is invertible at every
// sample, i.e. an ODE, with smooth terms (no piecewise-smooth ones: METHOD.md
// s.15). Otherwise, or when the extrapolation does not settle
// within the step budget, MonodromyResult::ok is false and `message` says why
// (continuation then takes Hill's method or the model's own monodromy).

#include <string>

#include <Eigen/Dense>

#include "rmhb/bifurcation.h"
#include "rmhb/harmonic_balance_problem.h"
#include "rmhb/harmonic_solution.h"

namespace rmhb {

struct HarmonicMonodromyOptions {
  // Largest difference between the two most extrapolated monodromy matrices
  // (Romberg's last correction), relative to max(1, max|Phi|); above it the
  // grid is refined, and past max_steps the method gives up.
  double tolerance = 1e-10;
  // The finest step h satisfies h max_t |B^-1 A|_inf <= max_step_rate.
  double max_step_rate = 0.1;
  int max_steps = 1 << 15;  // samples of the finest grid over one period
  // The grid to start from (a power of two; 0: from the harmonics), e.g.
  // the `suggested_samples` of a neighbouring solution on a branch: one
  // pass instead of a coarse one that sizes the grid.
  int initial_samples = 0;
  std::string IsValid() const;  // empty when valid
};

// Never throws for a solution outside the method's scope: ok = false.
// Throws std::invalid_argument for invalid options or a solution on other
// variables than the problem's.
// *suggested_samples (optional): the grid that would have met the tolerance
// with a margin, for initial_samples at a neighbouring solution.
MonodromyResult HarmonicMonodromy(const HarmonicBalanceProblem& problem, const HarmonicSolution& solution,
                                  const HarmonicMonodromyOptions& options = {}, int* suggested_samples = nullptr);

// An autonomous orbit's monodromy M maps the flow direction f onto itself
// (M f = f). In the basis [f/|f|, Q], Q an orthonormal complement,
// M = [1 a'; 0 Q' M Q]: the non-trivial multipliers are the eigenvalues of
// Q' M Q, and f' M f / f' f is the trivial one (index 0 of *multipliers,
// *trivial = 0). Taking them there, not from M, matters for a conservative
// orbit, whose second multiplier 1 forms a Jordan block with the trivial
// one: an O(e) error of M splits that pair by O(sqrt(e)), while Q' M Q keeps
// it at 1 + O(e).
void DeflateTrivialMultiplier(const Eigen::MatrixXd& monodromy, const Eigen::VectorXd& flow,
                              Multipliers* multipliers, int* trivial);

}  // namespace rmhb

#endif  // RMHB_HARMONIC_MONODROMY_H_

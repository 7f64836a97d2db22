#ifndef RMHB_EQUILIBRATION_H_
#define RMHB_EQUILIBRATION_H_

// Row and column equilibration of a Jacobian: diagonal D_r, D_c such that
// every row and every column of D_r J D_c has its largest entry in [1/2, 2).
//
// Why: a model written in engineering units (a MEMS resonator in SI: metres
// ~1e-6, newtons ~1e-9, a cubic stiffness ~1e11) gives residual rows and
// unknowns whose sizes differ by many orders. Absolute tests on max|F| and on
// the step then mean nothing, and partial pivoting picks pivots by the units
// rather than by the numbers. After equilibration, J_s = D_r J D_c does not
// depend on the units: if J' = P J Q with diagonal P, Q (a change of units of
// the equations and unknowns), Ruiz's iteration on J' converges to the same
// J_s (up to the power-of-two rounding below), with D_r' = D_r P^-1 and
// D_c' = Q^-1 D_c.
//
// Ruiz's iteration (D. Ruiz, "A scaling algorithm to equilibrate both rows
// and columns norms in matrices", RAL-TR-2001-034): each sweep divides every
// row and column by the square root of its infinity norm; it converges
// linearly, and a handful of sweeps are enough for a harmonic balance
// Jacobian. The factors are rounded to powers of two, so applying and undoing
// the scaling is exact in floating point (no rounding error is added, and a
// problem that is already well scaled gets D_r = D_c = I exactly). Each sweep
// is O(mn), negligible beside the O(n^3) factorisation it precedes.

#include <Eigen/Dense>
#include <Eigen/SparseCore>

namespace rmhb {

struct Equilibration {
  Eigen::VectorXd row;     // D_r, one factor per residual
  Eigen::VectorXd column;  // D_c, one factor per unknown
  int sweeps = 0;          // Ruiz sweeps done
};

// Power-of-two D_r, D_c for J (rows x columns). A zero row or column keeps
// the factor 1. Stops when a sweep changes no factor (then every nonzero row
// and column max of D_r J D_c is in [1/2, 2)), or after max_sweeps (then
// nearly so).
Equilibration Equilibrate(const Eigen::MatrixXd& J, int max_sweeps = 20);
// The same into *e, reusing its storage (no allocation once sized).
void Equilibrate(const Eigen::MatrixXd& J, Equilibration* e, int max_sweeps = 20);
// The same for a sparse J (its stored entries).
Equilibration Equilibrate(const Eigen::SparseMatrix<double>& J, int max_sweeps = 20);

// D_r = D_c = I: the unscaled problem, through the same code path.
Equilibration IdentityEquilibration(int rows, int columns);

}  // namespace rmhb

#endif  // RMHB_EQUILIBRATION_H_

#ifndef RMHB_INTERNAL_TRIANGULAR_SOLVE_H_
#define RMHB_INTERNAL_TRIANGULAR_SOLVE_H_

// Substitutions with a lower-triangular factor kept in the lower triangle of
// a column-major matrix (its columns read contiguously), for the small
// factorisations done by plain loops: DenseLu's unit L (dense_factorization.cc)
// and the regularised step's Cholesky factor (nonlinear_solver.cc).

#include <Eigen/Core>

namespace rmhb::internal {

enum class Diagonal { kUnit, kStored };

// b <- L^-1 b, a column at a time.
inline void LowerSolve(const Eigen::MatrixXd& L, Diagonal diagonal, double* b) {
  const Eigen::Index n = L.rows();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double* l = L.col(k).data();
    if (diagonal == Diagonal::kStored) b[k] /= l[k];
    for (Eigen::Index i = k + 1; i < n; ++i) b[i] -= l[i] * b[k];
  }
}

// b <- L'^-1 b: row k of L' is column k of L.
inline void LowerTransposedSolve(const Eigen::MatrixXd& L, Diagonal diagonal, double* b) {
  for (Eigen::Index k = L.rows() - 1; k >= 0; --k) {
    const double* l = L.col(k).data();
    double sum = b[k];
    for (Eigen::Index i = k + 1; i < L.rows(); ++i) sum -= l[i] * b[i];
    b[k] = diagonal == Diagonal::kStored ? sum / l[k] : sum;
  }
}

}  // namespace rmhb::internal

#endif  // RMHB_INTERNAL_TRIANGULAR_SOLVE_H_

#include "rmhb/equilibration.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace rmhb {
namespace {

// The power of two nearest 1/sqrt(m): m * factor^2 lands in [1/2, 2).
double InverseSqrtPowerOfTwo(double m) {
  if (!(m > 0) || !std::isfinite(m)) return 1.0;
  int exponent = 0;
  if (m >= std::numeric_limits<double>::min()) {
    // A normal number: frexp's exponent straight from the bits (m = f 2^e,
    // f in [1/2, 1), e = biased exponent - 1022), several times cheaper than
    // frexp and ldexp in the Monte Carlo's thousands of small equilibrations.
    std::uint64_t bits;
    std::memcpy(&bits, &m, sizeof bits);
    exponent = static_cast<int>((bits >> 52) & 0x7ff) - 1022;
  } else {
    std::frexp(m, &exponent);
  }
  // m in [2^(e-1), 2^e): the factor 2^-floor(e/2) puts m factor^2 in [1/2, 2).
  const int power = -(exponent >= 0 ? exponent / 2 : -((-exponent + 1) / 2));
  const std::uint64_t bits = static_cast<std::uint64_t>(power + 1023) << 52;  // |power| <= 538: normal
  double factor;
  std::memcpy(&factor, &bits, sizeof factor);
  return factor;
}

}  // namespace

Equilibration IdentityEquilibration(int rows, int columns) {
  return {Eigen::VectorXd::Ones(rows), Eigen::VectorXd::Ones(columns), 0};
}

namespace {

// Ruiz's sweeps into *e (its storage reused); maxima(e, row_max, column_max)
// sets the row and column maxima of |D_r J D_c| (zero for an empty row or
// column). The maxima live in the thread's own buffers: the Monte Carlo
// equilibrates hundreds of thousands of 7 x 7 Jacobians, where five
// allocations were most of the cost.
template <class Maxima>
void Sweeps(Eigen::Index m, Eigen::Index n, int max_sweeps, Maxima maxima, Equilibration* e) {
  e->row.setOnes(m);
  e->column.setOnes(n);
  thread_local Eigen::VectorXd row_max, column_max;
  row_max.resize(m);
  column_max.resize(n);
  for (e->sweeps = 0; e->sweeps < max_sweeps;) {
    maxima(*e, row_max, column_max);
    bool changed = false;
    for (Eigen::Index i = 0; i < m; ++i) {
      const double f = InverseSqrtPowerOfTwo(row_max(i));
      if (f != 1.0) e->row(i) *= f, changed = true;
    }
    for (Eigen::Index j = 0; j < n; ++j) {
      const double f = InverseSqrtPowerOfTwo(column_max(j));
      if (f != 1.0) e->column(j) *= f, changed = true;
    }
    if (!changed) break;
    ++e->sweeps;
  }
}

}  // namespace

void Equilibrate(const Eigen::MatrixXd& J, Equilibration* e, int max_sweeps) {
  // A fused pass per sweep over raw columns.
  const Eigen::Index m = J.rows();
  Sweeps(m, J.cols(), max_sweeps,
         [&](const Equilibration& e, Eigen::VectorXd& row_max, Eigen::VectorXd& column_max) {
           row_max.setZero();
           const double* r = e.row.data();
           double* rm = row_max.data();
           for (Eigen::Index j = 0; j < J.cols(); ++j) {
             const double* a = J.col(j).data();
             const double c = e.column(j);
             double cm = 0;
             for (Eigen::Index i = 0; i < m; ++i) {
               const double v = std::abs(a[i]) * r[i] * c;
               cm = std::max(cm, v);
               rm[i] = std::max(rm[i], v);
             }
             column_max(j) = cm;
           }
         },
         e);
}

Equilibration Equilibrate(const Eigen::MatrixXd& J, int max_sweeps) {
  Equilibration e;
  Equilibrate(J, &e, max_sweeps);
  return e;
}

Equilibration Equilibrate(const Eigen::SparseMatrix<double>& J, int max_sweeps) {
  Equilibration e;
  Sweeps(J.rows(), J.cols(), max_sweeps,
         [&](const Equilibration& e, Eigen::VectorXd& row_max, Eigen::VectorXd& column_max) {
           row_max.setZero();
           column_max.setZero();
           for (Eigen::Index j = 0; j < J.outerSize(); ++j)
             for (Eigen::SparseMatrix<double>::InnerIterator it(J, j); it; ++it) {
               const double a = std::abs(it.value()) * e.row(it.row()) * e.column(it.col());
               column_max(it.col()) = std::max(column_max(it.col()), a);
               row_max(it.row()) = std::max(row_max(it.row()), a);
             }
         },
         &e);
  return e;
}

}  // namespace rmhb

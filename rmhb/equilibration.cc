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

// Ruiz's sweeps over J's entries, visited column by column by
// for_each_entry(visit(i, j, a_ij)): one pass for both norms per sweep.
template <class ForEachEntry>
Equilibration Sweeps(Eigen::Index m, Eigen::Index n, int max_sweeps, ForEachEntry for_each_entry) {
  Equilibration e = IdentityEquilibration(static_cast<int>(m), static_cast<int>(n));
  Eigen::VectorXd row_max(m), column_max(n);
  for (e.sweeps = 0; e.sweeps < max_sweeps;) {
    row_max.setZero();
    column_max.setZero();
    for_each_entry([&](Eigen::Index i, Eigen::Index j, double value) {
      const double a = std::abs(value) * e.row(i) * e.column(j);
      column_max(j) = std::max(column_max(j), a);
      row_max(i) = std::max(row_max(i), a);
    });
    bool changed = false;
    for (Eigen::Index i = 0; i < m; ++i) {
      const double f = InverseSqrtPowerOfTwo(row_max(i));
      if (f != 1.0) e.row(i) *= f, changed = true;
    }
    for (Eigen::Index j = 0; j < n; ++j) {
      const double f = InverseSqrtPowerOfTwo(column_max(j));
      if (f != 1.0) e.column(j) *= f, changed = true;
    }
    if (!changed) break;
    ++e.sweeps;
  }
  return e;
}

}  // namespace

Equilibration Equilibrate(const Eigen::MatrixXd& J, int max_sweeps) {
  return Sweeps(J.rows(), J.cols(), max_sweeps, [&](auto visit) {
    for (Eigen::Index j = 0; j < J.cols(); ++j)
      for (Eigen::Index i = 0; i < J.rows(); ++i) visit(i, j, J(i, j));
  });
}

Equilibration Equilibrate(const Eigen::SparseMatrix<double>& J, int max_sweeps) {
  return Sweeps(J.rows(), J.cols(), max_sweeps, [&](auto visit) {
    for (Eigen::Index j = 0; j < J.outerSize(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(J, j); it; ++it)
        visit(it.row(), it.col(), it.value());
  });
}

}  // namespace rmhb

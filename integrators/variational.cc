#include "integrators/variational.h"

#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace rmhb::integrators {

Eigen::MatrixXd DifferenceJacobian(const OdeSystem& system, double t, const double* y0) {
  const int n = system.dimension;
  const double step = std::cbrt(std::numeric_limits<double>::epsilon());
  Eigen::MatrixXd jacobian(n, n);
  Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(y0, n), plus(n), minus(n);
  for (int i = 0; i < n; ++i) {
    const double h = step * (1 + std::abs(y0[i]));
    y(i) = y0[i] + h;
    system.rhs(t, y.data(), plus.data());
    y(i) = y0[i] - h;
    system.rhs(t, y.data(), minus.data());
    y(i) = y0[i];
    jacobian.col(i) = (plus - minus) / (2 * h);
  }
  return jacobian;
}

OdeSystem VariationalSystem(const OdeSystem& system, const JacobianFunction& jacobian_function) {
  const int n = system.dimension;
  OdeSystem augmented;
  augmented.dimension = n + n * n;
  augmented.rhs = [&system, jacobian_function, n](double t, const double* z, double* dz) {
    system.rhs(t, z, dz);
    Eigen::MatrixXd jacobian(n, n);
    if (jacobian_function) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows(n, n);
      jacobian_function(t, z, rows.data());
      jacobian = rows;
    } else {
      jacobian = DifferenceJacobian(system, t, z);
    }
    Eigen::Map<Eigen::MatrixXd>(dz + n, n, n) = jacobian * Eigen::Map<const Eigen::MatrixXd>(z + n, n, n);
  };
  return augmented;
}

Eigen::VectorXd VariationalStart(const Eigen::VectorXd& y0) {
  const long n = y0.size();
  Eigen::VectorXd z(n + n * n);
  z.head(n) = y0;
  Eigen::Map<Eigen::MatrixXd>(z.data() + n, n, n).setIdentity();
  return z;
}

}  // namespace rmhb::integrators

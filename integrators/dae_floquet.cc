#include "integrators/dae_floquet.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <Eigen/Eigenvalues>

#include "integrators/detail/validation.h"
#include "integrators/ida_integrator.h"

namespace rmhb::integrators {
namespace {

// dF/dv by central differences at (t, y, yp), v = y (wrt_derivative false)
// or yp; columns into `out` (n x n).
void ResidualDerivative(const DaeSystem& s, double t, const double* y, const double* yp, bool wrt_derivative,
                        Eigen::MatrixXd* out) {
  const int n = s.dimension;
  const double step = std::cbrt(std::numeric_limits<double>::epsilon());
  Eigen::VectorXd yy = Eigen::Map<const Eigen::VectorXd>(y, n), pp = Eigen::Map<const Eigen::VectorXd>(yp, n);
  Eigen::VectorXd plus(n), minus(n);
  Eigen::VectorXd& v = wrt_derivative ? pp : yy;
  for (int i = 0; i < n; ++i) {
    const double original = v(i), h = step * (1 + std::abs(original));
    v(i) = original + h;
    s.residual(t, yy.data(), pp.data(), plus.data());
    v(i) = original - h;
    s.residual(t, yy.data(), pp.data(), minus.data());
    v(i) = original;
    out->col(i) = (plus - minus) / (2 * h);
  }
}

}  // namespace

FloquetReport DaeFloquetMultipliers(const DaeSystem& system, const Eigen::VectorXd& y0, double t0, double period,
                                    const FloquetOptions& options) {
  constexpr const char* kCaller = "DaeFloquetMultipliers";
  detail::ValidateSystem(system, kCaller);
  detail::ValidateVector(y0, system.dimension, "y0", kCaller);
  detail::ValidateInitialTime(t0, kCaller);
  if (!(period > 0) || !std::isfinite(period))
    throw std::invalid_argument("DaeFloquetMultipliers: period must be finite and > 0");
  const auto start = std::chrono::steady_clock::now();
  const int n = system.dimension;
  std::vector<int> differential;
  for (int i = 0; i < n; ++i)
    if (system.differential.empty() || system.differential[i]) differential.push_back(i);
  const int k = static_cast<int>(differential.size());

  // State [y, Phi column by column] (n + n k).
  DaeSystem augmented;
  augmented.dimension = n + n * k;
  augmented.differential.assign(augmented.dimension, true);
  for (int c = 0; c <= k; ++c)
    for (int i = 0; i < n; ++i)
      augmented.differential[c * n + i] = system.differential.empty() || system.differential[i];
  augmented.residual = [&system, n, k](double t, const double* z, const double* zp, double* r) {
    system.residual(t, z, zp, r);
    Eigen::MatrixXd fy(n, n), fyp(n, n);
    ResidualDerivative(system, t, z, zp, false, &fy);
    ResidualDerivative(system, t, z, zp, true, &fyp);
    Eigen::Map<Eigen::MatrixXd>(r + n, n, k) = fy * Eigen::Map<const Eigen::MatrixXd>(z + n, n, k) +
                                               fyp * Eigen::Map<const Eigen::MatrixXd>(zp + n, n, k);
  };
  Eigen::VectorXd z0 = Eigen::VectorXd::Zero(augmented.dimension);
  z0.head(n) = y0;
  for (int j = 0; j < k; ++j) z0(n + j * n + differential[j]) = 1;

  FloquetReport report;
  const IntegrationResult r =
      IntegrateDae(augmented, z0, Eigen::VectorXd::Zero(augmented.dimension), t0, {t0 + period}, options.integrator);
  report.ok = r.ok();
  report.message = r.message;
  report.steps = r.steps;
  if (report.ok) {
    const Eigen::VectorXd end = r.trajectory.states.row(0).transpose();
    for (int j = 0; j < k; ++j)
      report.closure_error = std::max(report.closure_error, std::abs(end(differential[j]) - y0(differential[j])));
    report.monodromy.resize(k, k);
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) report.monodromy(i, j) = end(n + j * n + differential[i]);
    const Eigen::VectorXcd mu = Eigen::EigenSolver<Eigen::MatrixXd>(report.monodromy, false).eigenvalues();
    report.multipliers.assign(mu.data(), mu.data() + k);
    std::sort(report.multipliers.begin(), report.multipliers.end(),
              [](auto a, auto b) { return std::abs(a) > std::abs(b); });
    if (options.autonomous && k > 0) {
      report.trivial = 0;
      for (int i = 1; i < k; ++i)
        if (std::abs(report.multipliers[i] - 1.0) < std::abs(report.multipliers[report.trivial] - 1.0))
          report.trivial = i;
    }
    for (int i = 0; i < k; ++i)
      if (i != report.trivial) report.max_modulus = std::max(report.max_modulus, std::abs(report.multipliers[i]));
    report.stable = report.max_modulus < 1 - options.margin;
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace rmhb::integrators

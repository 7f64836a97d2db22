#include "integrators/floquet.h"

#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "integrators/cvode_integrator.h"
#include "integrators/detail/validation.h"
#include "integrators/variational.h"

namespace rmhb::integrators {

std::string FloquetReport::BriefReport() const {
  std::ostringstream out;
  out.precision(6);
  if (!ok) return "Floquet: integration failed: " + message;
  out << (stable ? "stable" : "unstable") << " (Floquet, CVODE): max|mu| " << max_modulus
      << ", multipliers";
  for (size_t i = 0; i < multipliers.size(); ++i)
    out << (static_cast<int>(i) == trivial ? " [" : " ") << multipliers[i]
        << (static_cast<int>(i) == trivial ? " trivial]" : "");
  out << ", closure " << closure_error;
  return out.str();
}

FloquetReport FloquetMultipliers(const OdeSystem& system, const Eigen::VectorXd& y0, double t0,
                                 double period, const FloquetOptions& options) {
  constexpr const char* kCaller = "FloquetMultipliers";
  detail::ValidateSystem(system, kCaller);
  detail::ValidateVector(y0, system.dimension, "y0", kCaller);
  detail::ValidateInitialTime(t0, kCaller);
  if (!(period > 0) || !std::isfinite(period))
    throw std::invalid_argument("FloquetMultipliers: period must be finite and > 0");
  const auto start = std::chrono::steady_clock::now();
  const int n = system.dimension;

  // State [y, Phi column by column], Phi(0) = I.
  const OdeSystem augmented = VariationalSystem(system, options.jacobian);
  const Eigen::VectorXd z0 = VariationalStart(y0);

  FloquetReport report;
  const IntegrationResult r = IntegrateOde(augmented, z0, t0, {t0 + period}, options.integrator);
  report.ok = r.ok();
  report.message = r.message;
  report.steps = r.steps;
  if (report.ok) {
    const Eigen::VectorXd end = r.trajectory.states.row(0).transpose();
    report.closure_error = (end.head(n) - y0).cwiseAbs().maxCoeff();
    report.monodromy = Eigen::Map<const Eigen::MatrixXd>(end.data() + n, n, n);
    const Eigen::VectorXcd mu = Eigen::EigenSolver<Eigen::MatrixXd>(report.monodromy, false).eigenvalues();
    report.multipliers.assign(mu.data(), mu.data() + n);
    std::sort(report.multipliers.begin(), report.multipliers.end(),
              [](auto a, auto b) { return std::abs(a) > std::abs(b); });
    if (options.autonomous) {
      report.trivial = 0;
      for (int i = 1; i < n; ++i)
        if (std::abs(report.multipliers[i] - 1.0) < std::abs(report.multipliers[report.trivial] - 1.0))
          report.trivial = i;
    }
    for (int i = 0; i < n; ++i)
      if (i != report.trivial) report.max_modulus = std::max(report.max_modulus, std::abs(report.multipliers[i]));
    report.stable = report.max_modulus < 1 - options.margin;
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace rmhb::integrators

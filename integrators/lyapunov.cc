#include "integrators/lyapunov.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/QR>

#include "integrators/cvode_integrator.h"
#include "integrators/detail/validation.h"

namespace rmhb::integrators {

std::string LyapunovOptions::IsValid() const {
  if (!(segment > 0) || !std::isfinite(segment)) return "segment must be finite and > 0";
  if (segments < 2) return "segments must be >= 2";
  return "";
}

std::string LyapunovReport::BriefReport() const {
  std::ostringstream out;
  if (!ok) return "Lyapunov exponents: integration failed: " + message;
  out.precision(6);
  out << "Lyapunov exponents";
  for (double l : exponents) out << " " << l;
  out << " (over t = " << time << ", converged to ~" << spread << ", " << steps << " steps, " << seconds * 1e3
      << " ms)";
  return out.str();
}

LyapunovReport LyapunovExponents(const OdeSystem& system, const Eigen::VectorXd& y0, double t0,
                                 const LyapunovOptions& options) {
  constexpr const char* kCaller = "LyapunovExponents";
  if (const std::string why = options.IsValid(); !why.empty())
    throw std::invalid_argument(std::string(kCaller) + ": " + why);
  detail::ValidateSystem(system, kCaller);
  detail::ValidateVector(y0, system.dimension, "y0", kCaller);
  detail::ValidateInitialTime(t0, kCaller);
  const auto start = std::chrono::steady_clock::now();
  const int n = system.dimension;
  const OdeSystem augmented = VariationalSystem(system, options.jacobian);
  Eigen::VectorXd z = VariationalStart(y0);
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n), half(n);
  LyapunovReport report;
  double t = t0;
  const int halfway = options.segments / 2;
  report.segment_states.resize(options.segments, n);
  for (int s = 0; s < options.segments; ++s) {
    // One segment per call: the QR below changes the state, which CVODE's
    // history must not carry over.
    const IntegrationResult r = IntegrateOde(augmented, z, t, {t + options.segment}, options.integrator);
    report.steps += r.steps;
    if (!r.ok()) {
      report.message = r.message;
      break;
    }
    t += options.segment;
    z = r.trajectory.states.row(0).transpose();
    report.segment_states.row(s) = z.head(n).transpose();
    Eigen::Map<Eigen::MatrixXd> phi(z.data() + n, n, n);
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(phi);
    const Eigen::MatrixXd R = qr.matrixQR().triangularView<Eigen::Upper>();
    Eigen::MatrixXd Q = qr.householderQ();
    for (int i = 0; i < n; ++i) {
      sum(i) += std::log(std::abs(R(i, i)));
      if (R(i, i) < 0) Q.col(i) = -Q.col(i);  // keep the frame's orientation continuous
    }
    phi = Q;
    if (s + 1 == halfway) half = sum / (t - t0);
  }
  report.time = t - t0;
  report.segment_states.conservativeResize(static_cast<long>(std::lround(report.time / options.segment)), n);
  report.ok = report.message.empty() && report.time > 0;
  if (report.ok) {
    const Eigen::VectorXd exponents = sum / report.time;
    report.spread = (exponents - half).cwiseAbs().maxCoeff();
    report.exponents.assign(exponents.data(), exponents.data() + n);
    std::sort(report.exponents.rbegin(), report.exponents.rend());
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace rmhb::integrators

#include "integrators/trajectory_validation.h"

#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "integrators/cvode_integrator.h"
#include "integrators/ida_integrator.h"

namespace rmhb::integrators {
namespace {

std::vector<double> UniformTimes(double t_end, int samples) {
  if (!(t_end > 0) || !std::isfinite(t_end))
    throw std::invalid_argument("ValidateTrajectory: t_end must be finite and > 0");
  if (samples < 2) throw std::invalid_argument("ValidateTrajectory: need at least 2 samples");
  std::vector<double> times(samples);
  for (int i = 0; i < samples; ++i) times[i] = t_end * i / (samples - 1);
  return times;
}

// Fills the report's status and largest deviation from the integration.
void Compare(const IntegrationResult& r, const std::function<Eigen::VectorXd(double)>& claimed,
             const std::vector<double>& times, ValidationReport* report) {
  report->samples = static_cast<int>(times.size());
  report->ok = r.ok();
  report->message = r.message;
  if (!r.ok()) {
    report->max_error = NAN;
    return;
  }
  for (std::size_t i = 0; i < times.size(); ++i) {
    const double e =
        (claimed(times[i]) - r.trajectory.states.row(static_cast<long>(i)).transpose()).cwiseAbs().maxCoeff();
    if (e > report->max_error) {
      report->max_error = e;
      report->error_time = times[i];
    }
  }
}

}  // namespace

ValidationReport ValidateDaeTrajectory(const DaeSystem& dae,
                                       const std::function<Eigen::VectorXd(double)>& claimed,
                                       double t_end, int samples) {
  const std::vector<double> times = UniformTimes(t_end, samples);
  const auto start = std::chrono::steady_clock::now();
  // IDA is BDF (order <= 5): its global error follows the tolerance down to
  // ~1e-14 (softening-dae over 2 periods: 2.5e-9 at rtol 1e-12, 2.7e-10 at
  // 1e-13, 1.1e-11 at 1e-14 in 28 ms; 1e-15 is refused).
  IntegratorOptions options;
  options.relative_tolerance = 1e-14;
  options.absolute_tolerance = 1e-16;
  ValidationReport report;
  report.integrator = "IDA BDF, rtol 1e-14";
  const Eigen::VectorXd y0 = claimed(0.0);
  const IntegrationResult r =
      IntegrateDae(dae, y0, Eigen::VectorXd::Zero(y0.size()), 0.0, times, options);
  Compare(r, claimed, times, &report);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

ValidationReport ValidateTrajectory(const OdeSystem& ode,
                                    const std::function<Eigen::VectorXd(double)>& claimed,
                                    double t_end, bool stiff, int samples) {
  const std::vector<double> times = UniformTimes(t_end, samples);
  const auto start = std::chrono::steady_clock::now();
  IntegratorOptions options;
  options.method = stiff ? IntegratorOptions::Method::kBdf : IntegratorOptions::Method::kAdams;
  // Adams reaches ~1e-13 relative on smooth problems; BDF (order 5) is
  // limited by its step count, so it gets a looser but still tight target.
  options.relative_tolerance = stiff ? 1e-12 : 1e-13;
  options.absolute_tolerance = stiff ? 1e-14 : 1e-15;
  ValidationReport report;
  std::ostringstream name;
  name << "CVODE " << (stiff ? "BDF" : "Adams") << ", rtol " << options.relative_tolerance;
  report.integrator = name.str();
  const IntegrationResult r = IntegrateOde(ode, claimed(0.0), 0.0, times, options);
  Compare(r, claimed, times, &report);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace rmhb::integrators

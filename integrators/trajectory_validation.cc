#include "integrators/trajectory_validation.h"

#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "integrators/cvode_integrator.h"

namespace rmhb::integrators {

ValidationReport ValidateTrajectory(const OdeSystem& ode,
                                    const std::function<Eigen::VectorXd(double)>& claimed,
                                    double t_end, bool stiff, int samples) {
  if (!(t_end > 0) || !std::isfinite(t_end))
    throw std::invalid_argument("ValidateTrajectory: t_end must be finite and > 0");
  if (samples < 2) throw std::invalid_argument("ValidateTrajectory: need at least 2 samples");
  const auto start = std::chrono::steady_clock::now();
  IntegratorOptions options;
  options.method = stiff ? IntegratorOptions::Method::kBdf : IntegratorOptions::Method::kAdams;
  // Adams reaches ~1e-13 relative on smooth problems; BDF (order 5) is
  // limited by its step count, so it gets a looser but still tight target.
  options.relative_tolerance = stiff ? 1e-12 : 1e-13;
  options.absolute_tolerance = stiff ? 1e-14 : 1e-15;
  std::vector<double> times(samples);
  for (int i = 0; i < samples; ++i) times[i] = t_end * i / (samples - 1);
  ValidationReport report;
  std::ostringstream name;
  name << "CVODE " << (stiff ? "BDF" : "Adams") << ", rtol " << options.relative_tolerance;
  report.integrator = name.str();
  report.samples = samples;
  const IntegrationResult r = IntegrateOde(ode, claimed(0.0), 0.0, times, options);
  report.ok = r.ok();
  report.message = r.message;
  if (r.ok()) {
    for (int i = 0; i < samples; ++i) {
      const double e = (claimed(times[i]) - r.trajectory.states.row(i).transpose()).cwiseAbs().maxCoeff();
      if (e > report.max_error) {
        report.max_error = e;
        report.error_time = times[i];
      }
    }
  } else {
    report.max_error = NAN;
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace rmhb::integrators

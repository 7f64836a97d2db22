#include "integrators/cvode_integrator.h"

#include <chrono>

#include "integrators/detail/cvode_session.h"
#include "integrators/detail/validation.h"

namespace rmhb::integrators {

IntegrationResult IntegrateOde(const OdeSystem& system, const Eigen::VectorXd& y0, double t0,
                               const std::vector<double>& output_times,
                               const IntegratorOptions& options) {
  constexpr const char* kCaller = "IntegrateOde";
  detail::ValidateSystem(system, kCaller);
  detail::ValidateVector(y0, system.dimension, "y0", kCaller);
  detail::ValidateInitialTime(t0, kCaller);
  detail::ValidateOutputTimes(output_times, t0, kCaller);
  detail::ValidateOptions(options, /*for_ida=*/false, kCaller);

  const auto start = std::chrono::steady_clock::now();
  IntegrationResult result;
  Trajectory& trajectory = result.trajectory;
  trajectory.states.resize(static_cast<Eigen::Index>(output_times.size()), system.dimension);
  trajectory.times.reserve(output_times.size());

  detail::CvodeSession session(system, y0, t0, options);
  result.solver = session.solver_name();
  if (session.ok()) {
    for (const double t_out : output_times) {
      const Eigen::Index row = trajectory.size();
      if (t_out == t0) {
        // CVODE rejects tout == t0 (CV_TOO_CLOSE); the answer is known anyway.
        trajectory.states.row(row) = y0.transpose();
      } else {
        double t_reached = t0;
        if (session.Advance(t_out, &t_reached) < 0) break;
        trajectory.states.row(row) =
            Eigen::Map<const Eigen::VectorXd>(session.state(), system.dimension).transpose();
      }
      trajectory.times.push_back(t_out);
    }
  }

  trajectory.states.conservativeResize(trajectory.size(), system.dimension);
  result.status = session.ok() ? IntegrationStatus::kSuccess : IntegrationStatus::kFailure;
  result.message = session.failure();
  result.steps = session.steps();
  result.rhs_evaluations = session.rhs_evaluations();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace rmhb::integrators

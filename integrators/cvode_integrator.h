// Explicit ODEs with SUNDIALS CVODE.

#ifndef RMHB_INTEGRATORS_CVODE_INTEGRATOR_H_
#define RMHB_INTEGRATORS_CVODE_INTEGRATOR_H_

#include <Eigen/Core>
#include <vector>

#include "integrators/integration_result.h"
#include "integrators/integrator_options.h"
#include "integrators/ode_system.h"

namespace rmhb::integrators {

// Integrates system from (t0, y0) forward and samples the solution at
// output_times, which must be strictly increasing and >= t0. An output time
// equal to t0 returns y0 bit for bit. Each sample is CVODE's interpolant at
// that time (CV_NORMAL), so dense output grids do not force small steps.
//
// Throws std::invalid_argument for misuse (empty rhs, dimension <= 0 or
// mismatched, non-finite y0 or times, bad options, unsorted output times).
// Solver failures come back as status kFailure with the reason in message.
IntegrationResult IntegrateOde(const OdeSystem& system, const Eigen::VectorXd& y0, double t0,
                               const std::vector<double>& output_times,
                               const IntegratorOptions& options = {});

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_CVODE_INTEGRATOR_H_

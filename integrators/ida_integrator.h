// Implicit DAEs with SUNDIALS IDA (variable-order BDF, dense Newton).

#ifndef RMHB_INTEGRATORS_IDA_INTEGRATOR_H_
#define RMHB_INTEGRATORS_IDA_INTEGRATOR_H_

#include <Eigen/Core>
#include <vector>

#include "integrators/integration_result.h"
#include "integrators/integrator_options.h"
#include "integrators/ode_system.h"

namespace rmhb::integrators {

// Integrates F(t, y, y') = 0 from (t0, y0, yp0) and samples y at
// output_times (strictly increasing, >= t0). IDA is index-1 only: recast
// higher-index constraints first.
//
// With options.compute_consistent_initial_condition (the default) the
// algebraic components of y0 and all of yp0 are treated as guesses and
// corrected by IDACalcIC; the differential components of y0 are kept. An
// output time equal to t0 then returns the corrected y0, since that is the
// state the trajectory actually starts from. options.method is ignored.
//
// Throws std::invalid_argument for misuse (see IntegrateOde, plus yp0 or
// differential of the wrong size). Solver failures, including a failed
// initial-condition calculation, come back as status kFailure.
IntegrationResult IntegrateDae(const DaeSystem& system, const Eigen::VectorXd& y0,
                               const Eigen::VectorXd& yp0, double t0,
                               const std::vector<double>& output_times,
                               const IntegratorOptions& options = {});

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_IDA_INTEGRATOR_H_

#ifndef RMHB_INTEGRATORS_TRAJECTORY_VALIDATION_H_
#define RMHB_INTEGRATORS_TRAJECTORY_VALIDATION_H_

// Validation of a harmonic balance result by what it claims: start the
// ORIGINAL equations at the solution's state at t = 0, integrate tightly
// with SUNDIALS, and compare the two trajectories along the way. It knows
// nothing of harmonic balance: the solution is just a function of time.

#include <functional>
#include <string>

#include <Eigen/Core>

#include "integrators/integrator_options.h"
#include "integrators/ode_system.h"

namespace rmhb::integrators {

struct ValidationReport {
  bool ok = false;            // the integration succeeded
  double max_error = 0;       // max over samples and components of |claimed - integrated|
  double error_time = 0;      // where it occurs
  int samples = 0;
  double seconds = 0;
  std::string integrator;     // e.g. "CVODE Adams, rtol 1e-13"
  std::string message;        // SUNDIALS' failure, if any
};

// `claimed(t)` is the state the solution predicts at time t. Compared at
// `samples` uniform times in [0, t_end]. Stiff systems use BDF.
ValidationReport ValidateTrajectory(const OdeSystem& ode,
                                    const std::function<Eigen::VectorXd(double)>& claimed,
                                    double t_end, bool stiff, int samples = 2001);

// The same for an implicit DAE F(t, y, y') = 0 (a model with algebraic
// equations), integrated with IDA (BDF, rtol 1e-14) from claimed(0). IDACalcIC
// computes y'(0) and corrects the algebraic components of claimed(0) before
// the first step, so a claimed state off the constraint shows as an error at
// t = 0 rather than as an integration failure.
ValidationReport ValidateDaeTrajectory(const DaeSystem& dae,
                                       const std::function<Eigen::VectorXd(double)>& claimed,
                                       double t_end, int samples = 2001);

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_TRAJECTORY_VALIDATION_H_

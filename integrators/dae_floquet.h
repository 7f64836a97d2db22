#ifndef RMHB_INTEGRATORS_DAE_FLOQUET_H_
#define RMHB_INTEGRATORS_DAE_FLOQUET_H_

// Floquet multipliers of a periodic orbit of an index-1 DAE F(t, y, y') = 0
// (the DAE counterpart of integrators/floquet.h): IDA integrates the orbit
// with its variational equations
//   F_y(t, y, y') Phi + F_y'(t, y, y') Phi' = 0
// over one period, one column of Phi per differential component d_j, started
// from the unit perturbation e_{d_j} (IDACalcIC makes its algebraic rows
// consistent: a perturbation of the differential state determines the
// algebraic one). The monodromy matrix is Phi(T) restricted to the
// differential rows: the map of the differential perturbations over one
// period, whose eigenvalues are the multipliers of the underlying ODE.
// F_y and F_y' are central differences of the residual with steps
// cbrt(u) (1 + |y_i|), as in floquet.h.

#include <Eigen/Core>

#include "integrators/floquet.h"
#include "integrators/ode_system.h"

namespace rmhb::integrators {

// options.jacobian is not used (DAE residuals have no explicit Jacobian
// here); options.integrator's tolerances are IDA's. Throws
// std::invalid_argument for misuse like FloquetMultipliers; integration
// failures (including a failed consistent initial condition) are ok = false.
FloquetReport DaeFloquetMultipliers(const DaeSystem& system, const Eigen::VectorXd& y0, double t0, double period,
                                    const FloquetOptions& options = {});

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_DAE_FLOQUET_H_

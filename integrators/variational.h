#ifndef RMHB_INTEGRATORS_VARIATIONAL_H_
#define RMHB_INTEGRATORS_VARIATIONAL_H_

// The variational equations of an ODE y' = f(t, y): the state [y, Phi]
// (Phi n x n, column-major after y) with Phi' = J(t, y) Phi. Shared by the
// Floquet multipliers (integrators/floquet.h: Phi over one period) and the
// Lyapunov exponents (integrators/lyapunov.h: Phi over segments,
// re-orthonormalised between them).
//
// J is the caller's when given (row-major n x n df/dy), otherwise central
// differences of f with steps cbrt(u) (1 + |y_i|): truncation ~u^(2/3)
// ~ 4e-11 relative.

#include <functional>

#include <Eigen/Dense>

#include "integrators/ode_system.h"

namespace rmhb::integrators {

using JacobianFunction = std::function<void(double t, const double* y, double* jacobian)>;

// df/dy at (t, y) by the central differences above (y: system.dimension
// entries).
Eigen::MatrixXd DifferenceJacobian(const OdeSystem& system, double t, const double* y);

// `system` must outlive the returned one.
OdeSystem VariationalSystem(const OdeSystem& system, const JacobianFunction& jacobian);

// The variational state at the start: [y0, Phi = I].
Eigen::VectorXd VariationalStart(const Eigen::VectorXd& y0);

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_VARIATIONAL_H_

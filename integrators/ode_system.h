// Problem descriptions handed to the SUNDIALS-backed integrators.
//
// Callbacks take raw pointers rather than Eigen types so that they can write
// straight into SUNDIALS' vectors without a copy; wrap them in Eigen::Map if
// vector arithmetic is convenient.

#ifndef RMHB_INTEGRATORS_ODE_SYSTEM_H_
#define RMHB_INTEGRATORS_ODE_SYSTEM_H_

#include <functional>
#include <vector>

namespace rmhb::integrators {

// Explicit ODE  y' = f(t, y).
struct OdeSystem {
  int dimension = 0;
  // Writes f(t, y) into ydot (length `dimension`). A non-finite entry in ydot,
  // or an exception, ends the integration with IntegrationStatus::kFailure:
  // retrying with a smaller step cannot repair a NaN that comes from the model.
  // Throwing is also the way to stop an integration from inside the model;
  // the exception's what() ends up in IntegrationResult::message.
  std::function<void(double t, const double* y, double* ydot)> rhs;
};

// Implicit DAE  F(t, y, y') = 0, solved with IDA.
struct DaeSystem {
  int dimension = 0;
  // Writes F(t, y, yp) into residual. Same failure rules as OdeSystem::rhs.
  std::function<void(double t, const double* y, const double* yp, double* residual)> residual;
  // differential[i] is true where y_i' appears in F (IDA's id vector). IDA
  // needs it both to make the initial condition consistent and to leave the
  // algebraic components out of the local error test. Empty means "all
  // differential", which is the right default for an implicit ODE.
  std::vector<bool> differential;
};

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_ODE_SYSTEM_H_

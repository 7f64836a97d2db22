// Piecewise-smooth ODEs integrated event by event (METHOD.md s.15): between
// switching surfaces the right-hand side is smooth, so CVODE keeps its order
// and accuracy; at a surface its root finding locates the crossing, the
// crossed switches change branch and the integration restarts there. A
// reference that steps across a kink would be smeared over the step (its
// error then falls only with the step size, not with the tolerance).

#ifndef RMHB_INTEGRATORS_SWITCHED_INTEGRATION_H_
#define RMHB_INTEGRATORS_SWITCHED_INTEGRATION_H_

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "integrators/integration_result.h"
#include "integrators/integrator_options.h"
#include "integrators/trajectory_validation.h"

namespace rmhb::integrators {

// y' = f(t, y) with `num_switches` switches. rhs evaluates f with switch k
// held on branch modes[k] (+1: its argument's positive side, -1: the
// negative side), whatever the argument's sign, and writes the switch
// arguments (the switching functions, smooth along either branch) into
// `arguments` when not null.
struct SwitchedOdeSystem {
  int dimension = 0;
  int num_switches = 0;
  std::function<void(double t, const double* y, const signed char* modes, double* ydot, double* arguments)>
      rhs;
  // Optional: the new mode of switch k when its argument crosses zero in
  // `direction` (+-1) at (t, y), or its first mode (direction 0), for
  // switches with more than two branches (a Coulomb friction term: slide
  // either way or stick). Empty: the crossing's direction, the argument's
  // side at the start.
  std::function<int(double t, const double* y, int k, int direction, const signed char* modes)> next_mode;
  // Optional: called at a crossing once the modes have changed (before:
  // the modes up to it), may change the state there (SwitchedMonodromy:
  // the saltation of the variational part).
  std::function<void(double t, double* y, const signed char* before, const signed char* after)> at_switch;
};

struct SwitchedIntegration {
  IntegrationResult result;  // the samples at the output times
  int events = 0;            // switches crossed
};

// From (t0, y0), the state at each of `output_times` (increasing, >= t0).
// The first modes are the signs of the arguments at t0 (an argument that is
// exactly zero takes the side it moves to). More than `max_events` crossings
// (a chattering or sliding motion, which this does not model) end the
// integration with status kFailure and a message saying so. Throws
// std::invalid_argument for misuse (as IntegrateOde).
SwitchedIntegration IntegrateSwitched(const SwitchedOdeSystem& system, const Eigen::VectorXd& y0, double t0,
                                      const std::vector<double>& output_times, const IntegratorOptions& options = {},
                                      int max_events = 100000);

// ValidateTrajectory for a switched system: CVODE Adams at rtol 1e-13 with
// the crossings located by root finding; `integrator` says how many.
ValidationReport ValidateSwitchedTrajectory(const SwitchedOdeSystem& system,
                                            const std::function<Eigen::VectorXd(double)>& claimed, double t_end,
                                            int samples = 2001);

// The monodromy matrix of the orbit from (0, y0) over [0, T]: y with its
// variational equations Phi' = f_y Phi, f_y by central differences on the
// frozen branch, integrated by IntegrateSwitched. At each crossing of switch
// k, Phi jumps by the saltation matrix (METHOD.md s.15)
//   S = I + (f+ - f-) grad g_k^T / (grad g_k . f- + dg_k/dt),
// f-+ the field before and after, g_k its argument (gradients by central
// differences): the identity where f is continuous (max, min, abs, clamp),
// the jump's effect for sign, heaviside and Coulomb (sliding into a stick
// phase included: f+ is then the stuck field). Empty with `failure` set when
// the integration fails.
Eigen::MatrixXd SwitchedMonodromy(const SwitchedOdeSystem& system, const Eigen::VectorXd& y0, double T,
                                  const IntegratorOptions& options, std::string* failure);

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_SWITCHED_INTEGRATION_H_

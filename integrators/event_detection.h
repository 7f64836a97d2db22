// Zero crossings of a scalar function along an ODE trajectory, located to
// near machine precision; the basis for measuring limit-cycle periods.

#ifndef RMHB_INTEGRATORS_EVENT_DETECTION_H_
#define RMHB_INTEGRATORS_EVENT_DETECTION_H_

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "integrators/integration_result.h"
#include "integrators/integrator_options.h"
#include "integrators/ode_system.h"

namespace rmhb::integrators {

using EventFunction = std::function<double(double t, const double* y)>;
// Several event functions at once: writes g_1 .. g_n at (t, y) into g.
using MultiEventFunction = std::function<void(double t, const double* y, double* g)>;

// Integrates system from (t0, y0) to t_end (> t0) and returns, in increasing
// order, the times in (t0, t_end] where g(t, y(t)) crosses zero in the given
// direction: +1 upward only, -1 downward only, 0 both. A zero of g exactly at
// t0 is not a crossing.
//
// CVODE brackets each root to ~100 u (|t| + |h|) (u = unit round-off); a
// secant iteration on g evaluated along CVODE's interpolating polynomial of
// the last step (CVodeGetDky) then polishes it to a few ulps of t. The
// remaining error is that of the trajectory itself, i.e. set by the
// tolerances in options.
//
// If info is not null it receives status, counts, timing, and in
// info->trajectory the crossing times with the interpolated states there.
// On solver failure the crossings found so far are returned and
// info->status is kFailure; pass info to be able to tell.
//
// Throws std::invalid_argument for misuse (as IntegrateOde, plus empty g,
// t_end <= t0, direction outside {-1, 0, 1}).
std::vector<double> FindCrossings(const OdeSystem& system, const Eigen::VectorXd& y0, double t0,
                                  double t_end, const EventFunction& g, int direction,
                                  const IntegratorOptions& options = {},
                                  IntegrationResult* info = nullptr);

// Period of an attracting limit cycle, the reference for self-excited
// oscillators without a closed form (Van der Pol): the crossings of g in
// `direction` from (0, y0) to t_end, the first `transient_crossings` dropped
// (the approach to the cycle), and the mean spacing of the rest,
// (last - first) / (count - 1), which divides the location error of each
// crossing by the number of periods. NaN when fewer than two crossings
// remain or the integration failed (then info, if given, says why).
double LimitCyclePeriod(const OdeSystem& system, const Eigen::VectorXd& y0, double t_end,
                        const EventFunction& g, int direction, int transient_crossings,
                        const IntegratorOptions& options = {}, IntegrationResult* info = nullptr);

// Returns of an autonomous trajectory to the section through y0 normal to
// the flow there, (y - y0) . f(0, y0) = 0, crossed in the flow's direction
// (as at t = 0), in (0, t_end]: their times, and in info->trajectory (when
// info is given) the states there. A periodic orbit through y0 returns to
// y0 itself after one period (to the tolerances); an orbit approaching an
// attractor returns elsewhere. Empty when f(0, y0) is zero or not finite.
std::vector<double> SectionReturns(const OdeSystem& system, const Eigen::VectorXd& y0, double t_end,
                                   const IntegratorOptions& options = {}, IntegrationResult* info = nullptr);

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_EVENT_DETECTION_H_

// Argument checks shared by the integrator front ends. Each throws
// std::invalid_argument whose message starts with the public function's name,
// so the caller sees which call was misused.

#ifndef RMHB_INTEGRATORS_DETAIL_VALIDATION_H_
#define RMHB_INTEGRATORS_DETAIL_VALIDATION_H_

#include <Eigen/Core>
#include <vector>

#include "integrators/integrator_options.h"
#include "integrators/ode_system.h"

namespace rmhb::integrators::detail {

void ValidateSystem(const OdeSystem& system, const char* caller);
void ValidateSystem(const DaeSystem& system, const char* caller);
void ValidateVector(const Eigen::VectorXd& v, int dimension, const char* name, const char* caller);
void ValidateInitialTime(double t0, const char* caller);
void ValidateOutputTimes(const std::vector<double>& output_times, double t0, const char* caller);
// for_ida: IDA is BDF only, so max_order is bounded by 5 regardless of method.
void ValidateOptions(const IntegratorOptions& options, bool for_ida, const char* caller);

}  // namespace rmhb::integrators::detail

#endif  // RMHB_INTEGRATORS_DETAIL_VALIDATION_H_

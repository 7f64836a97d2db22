// Outcome of one integration: never an exception for a solver failure, so
// that callers scanning parameters can record the failure and move on.

#ifndef RMHB_INTEGRATORS_INTEGRATION_RESULT_H_
#define RMHB_INTEGRATORS_INTEGRATION_RESULT_H_

#include <string>

#include "integrators/trajectory.h"

namespace rmhb::integrators {

enum class IntegrationStatus { kSuccess, kFailure };

const char* ToString(IntegrationStatus status);

struct IntegrationResult {
  IntegrationStatus status = IntegrationStatus::kFailure;
  // Empty on success. On failure: SUNDIALS' return flag name (e.g.
  // "CV_RHSFUNC_FAIL"), its own explanation, and ours when the cause was a
  // user callback (non-finite value or exception).
  std::string message;
  std::string solver;  // "CVODE/Adams", "CVODE/BDF" or "IDA/BDF".
  // On failure holds the outputs reached before the failure.
  Trajectory trajectory;
  long steps = 0;
  // Every call of the user's rhs / residual, including those SUNDIALS makes
  // for finite-difference Jacobians and initial-step estimation.
  long rhs_evaluations = 0;
  double seconds = 0.0;  // Wall time.

  bool ok() const { return status == IntegrationStatus::kSuccess; }
  // One line, for logs.
  std::string BriefReport() const;
};

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_INTEGRATION_RESULT_H_

#include "integrators/integration_result.h"

#include <cstdio>

namespace rmhb::integrators {

const char* ToString(IntegrationStatus status) {
  switch (status) {
    case IntegrationStatus::kSuccess:
      return "success";
    case IntegrationStatus::kFailure:
      return "failure";
  }
  return "unknown";
}

std::string IntegrationResult::BriefReport() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "%s: %s, %d outputs, %ld steps, %ld rhs evaluations, %.3g s",
                solver.empty() ? "integrator" : solver.c_str(), ToString(status), trajectory.size(),
                steps, rhs_evaluations, seconds);
  std::string report = buffer;
  if (!message.empty()) report += " (" + message + ")";
  return report;
}

}  // namespace rmhb::integrators

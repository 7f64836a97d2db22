#include "integrators/detail/diagnostics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace rmhb::integrators::detail {

void CaptureSundialsError(int error_code, const char* module, const char* function, char* msg,
                          void* user_data) {
  // Warnings (CV_WARNING == IDA_WARNING == 99) such as "t + h = t" do not
  // end the integration; keep them out of the failure message.
  if (error_code > 0 || user_data == nullptr) return;
  auto* diagnostics = static_cast<Diagnostics*>(user_data);
  diagnostics->sundials_error = std::string(module ? module : "SUNDIALS") +
                                "::" + (function ? function : "?") + ": " + (msg ? msg : "");
}

std::string ComposeFailureMessage(const std::string& flag_name, const Diagnostics& diagnostics) {
  std::string message = flag_name;
  const char* separator = ": ";
  for (const std::string* part : {&diagnostics.sundials_error, &diagnostics.callback_error}) {
    if (part->empty()) continue;
    message += separator + *part;
    separator = "; ";
  }
  return message;
}

int FirstNonFinite(const double* values, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(values[i])) return i;
  }
  return -1;
}

std::string NonFiniteMessage(const char* callback, double t, int index, double value) {
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer),
                "%s returned a non-finite value (%g) in component %d at t = %.17g", callback, value,
                index, t);
  return buffer;
}

std::string RoundOffStopMessage(const std::string& flag_name, double h, double t) {
  if (std::abs(h) > 16 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t))) return "";
  char where[96];
  std::snprintf(where, sizeof(where), "|h| = %.3g at t = %.17g", std::abs(h), t);
  return flag_name + ": the step size fell to the round-off of t (" + where +
         "): the solution is singular there (a blow-up, a pole of the equations)";
}

std::string CrawlStopMessage(const std::string& flag_name, double t_before, double t, double tout, long steps,
                             long steps_left) {
  const double advance = std::abs(t - t_before), rest = std::abs(tout - t);
  if (steps <= 0 || steps_left <= 0 || !(advance * double(steps_left) / double(steps) * 1000 < rest)) return "";
  char what[256];
  std::snprintf(what, sizeof(what),
                "%ld steps advanced t by %.3g only, to t = %.17g (%.3g left to %.6g: at that pace far beyond the "
                "%ld steps of the budget left)",
                steps, advance, t, rest, tout, steps_left);
  return flag_name + ": " + what +
         ": the solution cannot pass there or slides along a discontinuity of the equations (dry friction "
         "written with sign() sticking)";
}

}  // namespace rmhb::integrators::detail

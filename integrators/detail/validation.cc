#include "integrators/detail/validation.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rmhb::integrators::detail {
namespace {

[[noreturn]] void Fail(const char* caller, const std::string& what) {
  throw std::invalid_argument(std::string(caller) + ": " + what);
}

std::string Str(double x) {
  std::ostringstream out;
  out.precision(17);
  out << x;
  return out.str();
}

void CheckDimension(int dimension, const char* caller) {
  if (dimension <= 0) {
    Fail(caller, "system dimension must be positive, got " + std::to_string(dimension));
  }
}

}  // namespace

void ValidateSystem(const OdeSystem& system, const char* caller) {
  CheckDimension(system.dimension, caller);
  if (!system.rhs) Fail(caller, "OdeSystem::rhs is empty");
}

void ValidateSystem(const DaeSystem& system, const char* caller) {
  CheckDimension(system.dimension, caller);
  if (!system.residual) Fail(caller, "DaeSystem::residual is empty");
  if (!system.differential.empty() &&
      static_cast<int>(system.differential.size()) != system.dimension) {
    Fail(caller, "DaeSystem::differential has " + std::to_string(system.differential.size()) +
                     " entries but the dimension is " + std::to_string(system.dimension) +
                     " (leave it empty if every component is differential)");
  }
}

void ValidateVector(const Eigen::VectorXd& v, int dimension, const char* name, const char* caller) {
  if (v.size() != dimension) {
    Fail(caller, std::string(name) + " has size " + std::to_string(v.size()) +
                     " but the system dimension is " + std::to_string(dimension));
  }
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      Fail(caller,
           std::string(name) + "[" + std::to_string(i) + "] is not finite (" + Str(v[i]) + ")");
    }
  }
}

void ValidateInitialTime(double t0, const char* caller) {
  if (!std::isfinite(t0)) Fail(caller, "initial time is not finite (" + Str(t0) + ")");
}

void ValidateOutputTimes(const std::vector<double>& output_times, double t0, const char* caller) {
  if (output_times.empty()) Fail(caller, "no output times requested");
  for (std::size_t k = 0; k < output_times.size(); ++k) {
    const double t = output_times[k];
    const std::string where = "output_times[" + std::to_string(k) + "] = " + Str(t);
    if (!std::isfinite(t)) Fail(caller, where + " is not finite");
    if (t < t0) Fail(caller, where + " precedes t0 = " + Str(t0) + " (only forward integration)");
    if (k > 0 && !(t > output_times[k - 1])) {
      Fail(caller, where + " does not exceed the previous output time " + Str(output_times[k - 1]) +
                       " (times must be strictly increasing)");
    }
  }
}

void ValidateOptions(const IntegratorOptions& options, bool for_ida, const char* caller) {
  const double rtol = options.relative_tolerance;
  const double atol = options.absolute_tolerance;
  if (!(std::isfinite(rtol) && rtol > 0)) {
    Fail(caller, "relative_tolerance must be finite and positive, got " + Str(rtol));
  }
  if (!(std::isfinite(atol) && atol > 0)) {
    Fail(caller, "absolute_tolerance must be finite and positive, got " + Str(atol));
  }
  if (options.max_steps <= 0) {
    Fail(caller, "max_steps must be positive, got " + std::to_string(options.max_steps));
  }
  if (!(std::isfinite(options.max_step) && options.max_step >= 0)) {
    Fail(caller, "max_step must be finite and >= 0 (0 = unlimited), got " + Str(options.max_step));
  }
  if (!(std::isfinite(options.initial_step) && options.initial_step >= 0)) {
    Fail(caller,
         "initial_step must be finite and >= 0 (0 = automatic), got " + Str(options.initial_step));
  }
  const bool adams = !for_ida && options.method == IntegratorOptions::Method::kAdams;
  const int order_limit = adams ? 12 : 5;
  if (options.max_order < 0 || options.max_order > order_limit) {
    Fail(caller, "max_order must be in [0, " + std::to_string(order_limit) + "] for " +
                     (for_ida ? "IDA"
                      : adams ? "Adams"
                              : "BDF") +
                     " (0 = default), got " + std::to_string(options.max_order));
  }
}

}  // namespace rmhb::integrators::detail

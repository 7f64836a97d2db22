// Collects why a SUNDIALS call failed, instead of letting SUNDIALS print to
// stderr: a library must not write to the console, and the caller wants the
// reason in IntegrationResult::message.

#ifndef RMHB_INTEGRATORS_DETAIL_DIAGNOSTICS_H_
#define RMHB_INTEGRATORS_DETAIL_DIAGNOSTICS_H_

#include <string>

namespace rmhb::integrators::detail {

struct Diagnostics {
  std::string sundials_error;  // Last error text SUNDIALS reported.
  std::string callback_error;  // First reason a user callback was rejected.

  void RecordCallbackError(const std::string& what) {
    // The first error is the cause; later ones are usually its consequences.
    if (callback_error.empty()) callback_error = what;
  }
};

// Matches both CVErrHandlerFn and IDAErrHandlerFn; user_data is Diagnostics*.
void CaptureSundialsError(int error_code, const char* module, const char* function, char* msg,
                          void* user_data);

// "FLAG_NAME: sundials text; callback text", skipping empty parts.
std::string ComposeFailureMessage(const std::string& flag_name, const Diagnostics& diagnostics);

// Index of the first non-finite entry of values[0..n), or -1.
int FirstNonFinite(const double* values, int n);

// Describes a rejected callback output, e.g.
// "rhs returned a non-finite value (nan) in component 1 at t = 0.5".
std::string NonFiniteMessage(const char* callback, double t, int index, double value);

// A chunk of steps that ended with |h| <= 16 eps max(1, |t|): the step size
// fell to the round-off of t, where the solution is singular (a blow-up, a
// pole of the equations). The failure message for `flag_name`, or empty when
// h is larger: near such a point SUNDIALS keeps taking steps t + h = t and
// only the step budget stopped it (10^7 steps, 16-20 s).
std::string RoundOffStopMessage(const std::string& flag_name, double h, double t);

// Empty unless a chunk of `steps` steps that took t from t_before to t left
// the rest of the interval (to tout) out of reach of `steps_left` more at
// that pace by a factor of 1000: a solution sliding along a discontinuity
// of the right-hand side (sign(v) friction at stick) steps at ~1e-14 without
// ever reaching the round-off of t, and only the budget (10^7 steps, ~10 s)
// stopped it. Otherwise the flag, where, and why. CVODE only: IDA's corrector
// fails outright at such a point (ida_integrator_test).
std::string CrawlStopMessage(const std::string& flag_name, double t_before, double t, double tout, long steps,
                             long steps_left);

}  // namespace rmhb::integrators::detail

#endif  // RMHB_INTEGRATORS_DETAIL_DIAGNOSTICS_H_

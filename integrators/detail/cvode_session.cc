#include "integrators/detail/cvode_session.h"

#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <string>
#include <utility>

namespace rmhb::integrators::detail {
namespace {

std::string FlagName(int flag) {
  // SUNDIALS returns a malloc'ed copy; LeakSanitizer notices if it is kept.
  char* name = CVodeGetReturnFlagName(flag);
  std::string result = name ? name : "CV_UNKNOWN_FLAG";
  std::free(name);
  return result;
}

// Returning -1 rather than a positive "recoverable" value: CVODE would retry
// with a smaller step, but a NaN or an exception from the model does not go
// away with h, and retries only delay the failure.
//
// Once rejected, every later call is rejected too. The -1 alone is not
// enough: with the fixed-point corrector CVODE 6.4 treats the failure as a
// convergence failure and shrinks h, so a model that is NaN only beyond
// some t* made the solver creep towards t* with ever smaller steps until
// max_steps (10^7 by default, ~20 s). Rejecting everything turns that into
// repeated step failures, which CVODE gives up on after a few attempts.
int RhsTrampoline(double t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* callback = static_cast<CvodeSession::Callback*>(user_data);
  if (!callback->diagnostics->callback_error.empty()) return -1;
  ++callback->rhs_evaluations;
  const int n = callback->system->dimension;
  double* out = N_VGetArrayPointer(ydot);
  try {
    callback->system->rhs(t, N_VGetArrayPointer(y), out);
  } catch (const std::exception& e) {
    callback->diagnostics->RecordCallbackError(std::string("rhs threw: ") + e.what());
    return -1;
  } catch (...) {
    callback->diagnostics->RecordCallbackError("rhs threw a non-standard exception");
    return -1;
  }
  const int bad = FirstNonFinite(out, n);
  if (bad >= 0) {
    callback->diagnostics->RecordCallbackError(NonFiniteMessage("rhs", t, bad, out[bad]));
    return -1;
  }
  return 0;
}

int EventTrampoline(double t, N_Vector y, double* gout, void* user_data) {
  auto* callback = static_cast<CvodeSession::Callback*>(user_data);
  if (!callback->diagnostics->callback_error.empty()) return -1;
  try {
    gout[0] = (*callback->event)(t, N_VGetArrayPointer(y));
  } catch (const std::exception& e) {
    callback->diagnostics->RecordCallbackError(std::string("event function threw: ") + e.what());
    return -1;
  } catch (...) {
    callback->diagnostics->RecordCallbackError("event function threw a non-standard exception");
    return -1;
  }
  if (!std::isfinite(gout[0])) {
    callback->diagnostics->RecordCallbackError(NonFiniteMessage("event function", t, 0, gout[0]));
    return -1;
  }
  return 0;
}

int EventsTrampoline(double t, N_Vector y, double* gout, void* user_data) {
  auto* callback = static_cast<CvodeSession::Callback*>(user_data);
  if (!callback->diagnostics->callback_error.empty()) return -1;
  try {
    (*callback->events)(t, N_VGetArrayPointer(y), gout);
  } catch (const std::exception& e) {
    callback->diagnostics->RecordCallbackError(std::string("event functions threw: ") + e.what());
    return -1;
  }
  for (int i = 0; i < callback->num_events; ++i)
    if (!std::isfinite(gout[i])) {
      callback->diagnostics->RecordCallbackError(NonFiniteMessage("event function", t, i, gout[i]));
      return -1;
    }
  return 0;
}

}  // namespace

void CvodeMemDeleter::operator()(void* mem) const { CVodeFree(&mem); }

CvodeSession::CvodeSession(const OdeSystem& system, const Eigen::VectorXd& y0, double t0,
                           const IntegratorOptions& options, AdamsCorrector corrector)
    : options_(options),
      solver_name_(options.method == IntegratorOptions::Method::kAdams ? "CVODE/Adams"
                                                                       : "CVODE/BDF") {
  callback_.system = &system;
  callback_.diagnostics = &diagnostics_;
  const sunindextype n = system.dimension;

  context_ = MakeContext();
  if (!context_) {
    failure_ = "SUNContext_Create failed";
    return;
  }
  y_.reset(N_VNew_Serial(n, context_.get()));
  scratch_.reset(N_VNew_Serial(n, context_.get()));
  if (!y_ || !scratch_) {
    failure_ = "N_VNew_Serial failed";
    return;
  }
  Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(y_.get()), n) = y0;

  const bool adams = options.method == IntegratorOptions::Method::kAdams;
  mem_.reset(CVodeCreate(adams ? CV_ADAMS : CV_BDF, context_.get()));
  if (!mem_) {
    failure_ = "CVodeCreate failed";
    return;
  }
  void* mem = mem_.get();
  // The handler replaces SUNDIALS' default of printing to stderr, so install
  // it before any call that can fail.
  if (!Check(CVodeSetErrHandlerFn(mem, CaptureSundialsError, &diagnostics_),
             "CVodeSetErrHandlerFn") ||
      !Check(CVodeInit(mem, RhsTrampoline, t0, y_.get()), "CVodeInit") ||
      !Check(CVodeSStolerances(mem, options.relative_tolerance, options.absolute_tolerance),
             "CVodeSStolerances") ||
      !Check(CVodeSetUserData(mem, &callback_), "CVodeSetUserData")) {
    return;
  }

  if (adams && corrector == AdamsCorrector::kFixedPoint) {
    // Functional iteration needs no Jacobian, so no n+1 rhs calls per
    // finite-difference Jacobian and no O(n^3) LU. Measured with
    // tests/integrators/adams_corrector_benchmark (pendulum, 10 periods,
    // rtol 1e-13, atol 1e-15, Release): fixed point 2900 steps, 4474 rhs
    // calls, 3.9 ms, error 1.3e-10; Newton + dense FD Jacobian 2963 steps,
    // 3712 rhs calls, 4.3 ms, error 5.7e-11. Same accuracy class (at rtol
    // 1e-12 fixed point was the more accurate one, 3.9e-10 vs 9.4e-10) and
    // ~10% faster at every tolerance tried (1e-10, 1e-12, 1e-13). Newton
    // only wins on rhs count, which matters for an expensive rhs, and a
    // problem stiff enough to need Newton wants BDF anyway.
    nonlinear_solver_.reset(SUNNonlinSol_FixedPoint(y_.get(), 0, context_.get()));
    if (!nonlinear_solver_) {
      failure_ = "SUNNonlinSol_FixedPoint failed";
      return;
    }
    if (!Check(CVodeSetNonlinearSolver(mem, nonlinear_solver_.get()), "CVodeSetNonlinearSolver")) {
      return;
    }
  } else {
    // Dense Newton with CVODE's internal difference-quotient Jacobian.
    failure_ = MakeDenseLinearSolver(n, y_.get(), context_.get(), &matrix_, &linear_solver_);
    if (!failure_.empty()) return;
    if (!Check(CVodeSetLinearSolver(mem, linear_solver_.get(), matrix_.get()),
               "CVodeSetLinearSolver")) {
      return;
    }
  }

  if (options.max_step > 0 && !Check(CVodeSetMaxStep(mem, options.max_step), "CVodeSetMaxStep")) {
    return;
  }
  if (options.initial_step > 0 &&
      !Check(CVodeSetInitStep(mem, options.initial_step), "CVodeSetInitStep")) {
    return;
  }
  if (options.max_order > 0 && !Check(CVodeSetMaxOrd(mem, options.max_order), "CVodeSetMaxOrd")) {
    return;
  }
  // At tight tolerances on long runs "t + h = t" warnings are expected and
  // harmless; they would only fill the captured error text.
  Check(CVodeSetMaxHnilWarns(mem, -1), "CVodeSetMaxHnilWarns");
}

bool CvodeSession::Check(int flag, const char* call) {
  if (flag >= 0) return true;
  failure_ = std::string(call) + " failed: " + ComposeFailureMessage(FlagName(flag), diagnostics_);
  return false;
}

bool CvodeSession::SetEventFunction(const EventFunction* g, int direction) {
  callback_.event = g;
  int rootdir = direction;
  return Check(CVodeRootInit(mem_.get(), 1, EventTrampoline), "CVodeRootInit") &&
         Check(CVodeSetRootDirection(mem_.get(), &rootdir), "CVodeSetRootDirection") &&
         // g often vanishes at t0 by construction (e.g. a velocity started at
         // rest); that is not worth a warning.
         Check(CVodeSetNoInactiveRootWarn(mem_.get()), "CVodeSetNoInactiveRootWarn");
}

bool CvodeSession::SetEventFunctions(int count, const MultiEventFunction* g) {
  callback_.events = g;
  callback_.num_events = count;
  return Check(CVodeRootInit(mem_.get(), count, EventsTrampoline), "CVodeRootInit") &&
         Check(CVodeSetNoInactiveRootWarn(mem_.get()), "CVodeSetNoInactiveRootWarn");
}

bool CvodeSession::RootsFound(int* found) { return Check(CVodeGetRootInfo(mem_.get(), found), "CVodeGetRootInfo"); }

int CvodeSession::Advance(double tout, double* t_reached) {
  const long remaining = options_.max_steps - steps();
  if (remaining <= 0) {
    failure_ = FlagName(CV_TOO_MUCH_WORK) +
               ": the budget of max_steps = " + std::to_string(options_.max_steps) +
               " steps is used up";
    return CV_TOO_MUCH_WORK;
  }
  // In chunks of steps, so that a step size stuck at the round-off of t is
  // seen: near a singularity the solution cannot pass (1/(1 - x)^2 as x -> 1,
  // a MEMS plate's pull-in) CVODE keeps taking steps t + h = t and only the
  // budget stops it, 10^7 steps and 16 s later.
  constexpr long kChunk = 100'000;
  int flag = CV_TOO_MUCH_WORK;
  for (long left = remaining; left > 0 && flag == CV_TOO_MUCH_WORK; left -= kChunk) {
    double t_before = *t_reached;
    CVodeGetCurrentTime(mem_.get(), &t_before);
    CVodeSetMaxNumSteps(mem_.get(), std::min(left, kChunk));
    flag = CVode(mem_.get(), tout, y_.get(), t_reached, CV_NORMAL);
    if (flag != CV_TOO_MUCH_WORK) break;
    double t_current = *t_reached, h_last = 0;
    CVodeGetCurrentTime(mem_.get(), &t_current);
    CVodeGetLastStep(mem_.get(), &h_last);
    if (std::string stuck = RoundOffStopMessage(FlagName(CV_TOO_MUCH_WORK), h_last, t_current); !stuck.empty()) {
      failure_ = std::move(stuck);
      return CV_TOO_MUCH_WORK;
    }
    if (std::string crawl = CrawlStopMessage(FlagName(CV_TOO_MUCH_WORK), t_before, t_current, tout,
                                             std::min(left, kChunk), left - kChunk);
        !crawl.empty()) {
      failure_ = std::move(crawl);
      return CV_TOO_MUCH_WORK;
    }
  }
  if (flag < 0) {
    double t_current = *t_reached;
    CVodeGetCurrentTime(mem_.get(), &t_current);
    char where[64];
    std::snprintf(where, sizeof(where), " (integration stopped at t = %.17g)", t_current);
    failure_ = ComposeFailureMessage(FlagName(flag), diagnostics_) + where;
  }
  return flag;
}

bool CvodeSession::Interpolate(double t, Eigen::VectorXd* y) {
  // A rejected t is the caller's probe going out of range, not a solver
  // failure: keep its complaint out of any later failure message.
  const std::string saved = diagnostics_.sundials_error;
  if (CVodeGetDky(mem_.get(), t, 0, scratch_.get()) != CV_SUCCESS) {
    diagnostics_.sundials_error = saved;
    return false;
  }
  *y = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(scratch_.get()),
                                         N_VGetLength(scratch_.get()));
  return true;
}

void CvodeSession::LastStepInterval(double* t_begin, double* t_end) const {
  double t_current = 0.0, h_last = 0.0;
  CVodeGetCurrentTime(mem_.get(), &t_current);
  CVodeGetLastStep(mem_.get(), &h_last);
  *t_begin = t_current - h_last;
  *t_end = t_current;
}

long CvodeSession::steps() const {
  long steps = 0;
  if (mem_) CVodeGetNumSteps(mem_.get(), &steps);
  return steps;
}

}  // namespace rmhb::integrators::detail

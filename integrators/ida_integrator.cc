#include "integrators/ida_integrator.h"

#include <ida/ida.h>
#include <ida/ida_ls.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <utility>

#include "integrators/detail/diagnostics.h"
#include "integrators/detail/sundials_handles.h"
#include "integrators/detail/validation.h"

namespace rmhb::integrators {
namespace {

using detail::Diagnostics;

std::string FlagName(int flag) {
  char* name = IDAGetReturnFlagName(flag);  // malloc'ed by SUNDIALS.
  std::string result = name ? name : "IDA_UNKNOWN_FLAG";
  std::free(name);
  return result;
}

struct IdaMemDeleter {
  void operator()(void* mem) const { IDAFree(&mem); }
};

struct Callback {
  const DaeSystem* system = nullptr;
  Diagnostics* diagnostics = nullptr;
  long residual_evaluations = 0;
};

// Unrecoverable (-1), and sticky once rejected, for the same reasons as the
// CVODE rhs (see detail/cvode_session.cc): a NaN from the model does not
// disappear with a smaller step, and no retry path may creep towards it.
int ResidualTrampoline(double t, N_Vector y, N_Vector yp, N_Vector residual, void* user_data) {
  auto* callback = static_cast<Callback*>(user_data);
  if (!callback->diagnostics->callback_error.empty()) return -1;
  ++callback->residual_evaluations;
  double* out = N_VGetArrayPointer(residual);
  try {
    callback->system->residual(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), out);
  } catch (const std::exception& e) {
    callback->diagnostics->RecordCallbackError(std::string("residual threw: ") + e.what());
    return -1;
  } catch (...) {
    callback->diagnostics->RecordCallbackError("residual threw a non-standard exception");
    return -1;
  }
  const int bad = detail::FirstNonFinite(out, callback->system->dimension);
  if (bad >= 0) {
    callback->diagnostics->RecordCallbackError(
        detail::NonFiniteMessage("residual", t, bad, out[bad]));
    return -1;
  }
  return 0;
}

// Owns everything one IDA run allocates; members are released in reverse
// order, so the IDA memory goes before the objects it refers to.
class IdaRun {
 public:
  IdaRun(const DaeSystem& system, const Eigen::VectorXd& y0, const Eigen::VectorXd& yp0, double t0,
         const IntegratorOptions& options)
      : options_(options) {
    callback_.system = &system;
    callback_.diagnostics = &diagnostics_;
    const sunindextype n = system.dimension;

    context_ = detail::MakeContext();
    if (!context_) {
      failure_ = "SUNContext_Create failed";
      return;
    }
    y_.reset(N_VNew_Serial(n, context_.get()));
    yp_.reset(N_VNew_Serial(n, context_.get()));
    id_.reset(N_VNew_Serial(n, context_.get()));
    if (!y_ || !yp_ || !id_) {
      failure_ = "N_VNew_Serial failed";
      return;
    }
    Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(y_.get()), n) = y0;
    Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(yp_.get()), n) = yp0;
    double* id = N_VGetArrayPointer(id_.get());
    for (sunindextype i = 0; i < n; ++i) {
      const bool differential = system.differential.empty() || system.differential[i];
      id[i] = differential ? 1.0 : 0.0;
      has_algebraic_ = has_algebraic_ || !differential;
    }

    mem_.reset(IDACreate(context_.get()));
    if (!mem_) {
      failure_ = "IDACreate failed";
      return;
    }
    void* mem = mem_.get();
    failure_ = detail::MakeDenseLinearSolver(n, y_.get(), context_.get(), &matrix_, &linear_solver_);
    if (!failure_.empty()) return;
    if (!Check(IDASetErrHandlerFn(mem, detail::CaptureSundialsError, &diagnostics_),
               "IDASetErrHandlerFn") ||
        !Check(IDAInit(mem, ResidualTrampoline, t0, y_.get(), yp_.get()), "IDAInit") ||
        !Check(IDASStolerances(mem, options.relative_tolerance, options.absolute_tolerance),
               "IDASStolerances") ||
        !Check(IDASetUserData(mem, &callback_), "IDASetUserData") ||
        !Check(IDASetLinearSolver(mem, linear_solver_.get(), matrix_.get()),
               "IDASetLinearSolver") ||
        // Needed by IDACalcIC to know which components it may change, and by
        // the error test suppression below.
        !Check(IDASetId(mem, id_.get()), "IDASetId")) {
      return;
    }
    // Algebraic components are determined by the differential ones; letting
    // them into the error test only forces needlessly small steps when they
    // have large or rapidly varying values.
    if (has_algebraic_ && !Check(IDASetSuppressAlg(mem, SUNTRUE), "IDASetSuppressAlg")) return;
    if (options.max_step > 0 && !Check(IDASetMaxStep(mem, options.max_step), "IDASetMaxStep")) {
      return;
    }
    if (options.initial_step > 0 &&
        !Check(IDASetInitStep(mem, options.initial_step), "IDASetInitStep")) {
      return;
    }
    if (options.max_order > 0 && !Check(IDASetMaxOrd(mem, options.max_order), "IDASetMaxOrd")) {
      return;
    }
  }

  bool ok() const { return failure_.empty(); }
  const std::string& failure() const { return failure_; }

  // tout1 only sets IDACalcIC's step scale; it must differ from t0.
  bool MakeConsistent(double tout1, Eigen::VectorXd* y0_consistent) {
    const int flag = IDACalcIC(mem_.get(), IDA_YA_YDP_INIT, tout1);
    if (flag < 0) {
      failure_ = "IDACalcIC failed to make the initial condition consistent: " +
                 detail::ComposeFailureMessage(FlagName(flag), diagnostics_);
      return false;
    }
    if (!Check(IDAGetConsistentIC(mem_.get(), y_.get(), yp_.get()), "IDAGetConsistentIC")) {
      return false;
    }
    *y0_consistent = state();
    return true;
  }

  int Advance(double tout, double* t_reached) {
    const long remaining = options_.max_steps - steps();
    if (remaining <= 0) {
      failure_ = FlagName(IDA_TOO_MUCH_WORK) +
                 ": the budget of max_steps = " + std::to_string(options_.max_steps) +
                 " steps is used up";
      return IDA_TOO_MUCH_WORK;
    }
    // In chunks of steps, as CVODE's session (cvode_session.cc): at a
    // singularity the solution cannot pass, IDA's steps fall to the round-off
    // of t and only the budget stopped it, 10^7 steps and 20 s later.
    constexpr long kChunk = 100'000;
    int flag = IDA_TOO_MUCH_WORK;
    for (long left = remaining; left > 0 && flag == IDA_TOO_MUCH_WORK; left -= kChunk) {
      IDASetMaxNumSteps(mem_.get(), std::min(left, kChunk));
      flag = IDASolve(mem_.get(), tout, t_reached, y_.get(), yp_.get(), IDA_NORMAL);
      if (flag != IDA_TOO_MUCH_WORK) break;
      double t_current = *t_reached, h_last = 0;
      IDAGetCurrentTime(mem_.get(), &t_current);
      IDAGetLastStep(mem_.get(), &h_last);
      if (std::string stuck = detail::RoundOffStopMessage(FlagName(IDA_TOO_MUCH_WORK), h_last, t_current); !stuck.empty()) {
        failure_ = std::move(stuck);
        return IDA_TOO_MUCH_WORK;
      }
    }
    if (flag < 0) {
      double t_current = *t_reached;
      IDAGetCurrentTime(mem_.get(), &t_current);
      char where[64];
      std::snprintf(where, sizeof(where), " (integration stopped at t = %.17g)", t_current);
      failure_ = detail::ComposeFailureMessage(FlagName(flag), diagnostics_) + where;
    }
    return flag;
  }

  Eigen::VectorXd state() const {
    return Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(y_.get()), N_VGetLength(y_.get()));
  }

  long steps() const {
    long steps = 0;
    if (mem_) IDAGetNumSteps(mem_.get(), &steps);
    return steps;
  }
  long residual_evaluations() const { return callback_.residual_evaluations; }

 private:
  bool Check(int flag, const char* call) {
    if (flag >= 0) return true;
    failure_ = std::string(call) +
               " failed: " + detail::ComposeFailureMessage(FlagName(flag), diagnostics_);
    return false;
  }

  const IntegratorOptions options_;
  Diagnostics diagnostics_;
  Callback callback_;
  std::string failure_;
  bool has_algebraic_ = false;
  detail::ContextHandle context_;
  detail::VectorHandle y_;
  detail::VectorHandle yp_;
  detail::VectorHandle id_;
  detail::MatrixHandle matrix_;
  detail::LinearSolverHandle linear_solver_;
  std::unique_ptr<void, IdaMemDeleter> mem_;
};

}  // namespace

IntegrationResult IntegrateDae(const DaeSystem& system, const Eigen::VectorXd& y0,
                               const Eigen::VectorXd& yp0, double t0,
                               const std::vector<double>& output_times,
                               const IntegratorOptions& options) {
  constexpr const char* kCaller = "IntegrateDae";
  detail::ValidateSystem(system, kCaller);
  detail::ValidateVector(y0, system.dimension, "y0", kCaller);
  detail::ValidateVector(yp0, system.dimension, "yp0", kCaller);
  detail::ValidateInitialTime(t0, kCaller);
  detail::ValidateOutputTimes(output_times, t0, kCaller);
  detail::ValidateOptions(options, /*for_ida=*/true, kCaller);

  const auto start = std::chrono::steady_clock::now();
  IntegrationResult result;
  result.solver = "IDA/BDF";
  Trajectory& trajectory = result.trajectory;
  trajectory.states.resize(static_cast<Eigen::Index>(output_times.size()), system.dimension);
  trajectory.times.reserve(output_times.size());

  IdaRun run(system, y0, yp0, t0, options);
  Eigen::VectorXd initial_state = y0;
  if (run.ok() && options.compute_consistent_initial_condition) {
    // IDACalcIC scales its trial step by the first output time ahead. With
    // only t0 requested any scale will do: the corrected state is still the
    // honest answer for that output.
    double tout1 = t0 + 1.0;
    for (const double t_out : output_times) {
      if (t_out > t0) {
        tout1 = t_out;
        break;
      }
    }
    run.MakeConsistent(tout1, &initial_state);
  }
  if (run.ok()) {
    for (const double t_out : output_times) {
      const Eigen::Index row = trajectory.size();
      if (t_out == t0) {
        trajectory.states.row(row) = initial_state.transpose();
      } else {
        double t_reached = t0;
        if (run.Advance(t_out, &t_reached) < 0) break;
        trajectory.states.row(row) = run.state().transpose();
      }
      trajectory.times.push_back(t_out);
    }
  }

  trajectory.states.conservativeResize(trajectory.size(), system.dimension);
  result.status = run.ok() ? IntegrationStatus::kSuccess : IntegrationStatus::kFailure;
  result.message = run.failure();
  result.steps = run.steps();
  result.rhs_evaluations = run.residual_evaluations();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace rmhb::integrators

// One configured CVODE instance with the callbacks wired to an OdeSystem.
// Shared by IntegrateOde and FindCrossings so both get identical solver
// settings, failure reporting and accounting.

#ifndef RMHB_INTEGRATORS_DETAIL_CVODE_SESSION_H_
#define RMHB_INTEGRATORS_DETAIL_CVODE_SESSION_H_

#include <Eigen/Core>
#include <memory>
#include <string>

#include "integrators/detail/diagnostics.h"
#include "integrators/detail/sundials_handles.h"
#include "integrators/event_detection.h"
#include "integrators/integrator_options.h"
#include "integrators/ode_system.h"

namespace rmhb::integrators::detail {

struct CvodeMemDeleter {
  void operator()(void* mem) const;
};

// How Adams' implicit corrector is solved. Kept selectable for measurement
// (tests/integrators/adams_corrector_benchmark); production uses the default.
enum class AdamsCorrector { kFixedPoint, kNewton };

class CvodeSession {
 public:
  // Arguments must already be validated. On setup failure ok() is false and
  // failure() says why.
  CvodeSession(const OdeSystem& system, const Eigen::VectorXd& y0, double t0,
               const IntegratorOptions& options,
               AdamsCorrector corrector = AdamsCorrector::kFixedPoint);
  CvodeSession(const CvodeSession&) = delete;
  CvodeSession& operator=(const CvodeSession&) = delete;

  bool ok() const { return failure_.empty(); }
  const std::string& failure() const { return failure_; }
  const char* solver_name() const { return solver_name_; }

  // Enables CVODE's root finding on a single event function; direction as
  // in FindCrossings. g must outlive the session.
  bool SetEventFunction(const EventFunction* g, int direction);
  // Root finding on `count` functions at once, both directions (switching
  // surfaces, integrators/switched_integration.h); g must outlive the
  // session. After a CV_ROOT_RETURN, RootsFound fills one entry per
  // function: +1 rising through zero, -1 falling, 0 none.
  bool SetEventFunctions(int count, const MultiEventFunction* g);
  bool RootsFound(int* found);

  // CVode(..., CV_NORMAL) towards tout with what is left of the step budget.
  // Returns CVODE's flag; a negative flag also sets failure().
  int Advance(double tout, double* t_reached);

  // The state CVODE returned from the last Advance.
  const double* state() const { return N_VGetArrayPointer(y_.get()); }

  // y(t) from the interpolating polynomial of the last step (CVodeGetDky);
  // t must lie within that step. Returns false otherwise.
  bool Interpolate(double t, Eigen::VectorXd* y);
  // [t_n - h_last, t_n]: where Interpolate is valid.
  void LastStepInterval(double* t_begin, double* t_end) const;

  long steps() const;
  long rhs_evaluations() const { return callback_.rhs_evaluations; }

  // Callback state CVODE hands back to the trampolines as user_data.
  struct Callback {
    const OdeSystem* system = nullptr;
    const EventFunction* event = nullptr;
    const MultiEventFunction* events = nullptr;
    int num_events = 0;
    Diagnostics* diagnostics = nullptr;
    long rhs_evaluations = 0;
  };

 private:
  bool Check(int flag, const char* call);

  const IntegratorOptions options_;
  const char* solver_name_;
  Diagnostics diagnostics_;
  Callback callback_;
  std::string failure_;
  // Declaration order is release order reversed: the CVODE memory goes first,
  // the context it was created in last.
  ContextHandle context_;
  VectorHandle y_;
  VectorHandle scratch_;
  MatrixHandle matrix_;
  LinearSolverHandle linear_solver_;
  NonlinearSolverHandle nonlinear_solver_;
  std::unique_ptr<void, CvodeMemDeleter> mem_;
};

}  // namespace rmhb::integrators::detail

#endif  // RMHB_INTEGRATORS_DETAIL_CVODE_SESSION_H_

// Owning handles for SUNDIALS objects. Every early return in the front ends
// must release what was created so far; the test suite runs under
// LeakSanitizer, so this is not optional.

#ifndef RMHB_INTEGRATORS_DETAIL_SUNDIALS_HANDLES_H_
#define RMHB_INTEGRATORS_DETAIL_SUNDIALS_HANDLES_H_

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nonlinearsolver.h>

#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <memory>
#include <string>
#include <type_traits>

namespace rmhb::integrators::detail {

struct ContextDeleter {
  void operator()(SUNContext context) const { SUNContext_Free(&context); }
};
struct VectorDeleter {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
struct MatrixDeleter {
  void operator()(SUNMatrix m) const { SUNMatDestroy(m); }
};
struct LinearSolverDeleter {
  void operator()(SUNLinearSolver s) const { SUNLinSolFree(s); }
};
struct NonlinearSolverDeleter {
  void operator()(SUNNonlinearSolver s) const { SUNNonlinSolFree(s); }
};

using ContextHandle = std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextDeleter>;
using VectorHandle = std::unique_ptr<std::remove_pointer_t<N_Vector>, VectorDeleter>;
using MatrixHandle = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, MatrixDeleter>;
using LinearSolverHandle =
    std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, LinearSolverDeleter>;
using NonlinearSolverHandle =
    std::unique_ptr<std::remove_pointer_t<SUNNonlinearSolver>, NonlinearSolverDeleter>;

// Null on failure (SUNDIALS only fails here when out of memory).
inline ContextHandle MakeContext() {
  SUNContext context = nullptr;
  // SUNDIALS 6.x takes a communicator as void*; null means "no MPI".
  if (SUNContext_Create(nullptr, &context) != 0) return ContextHandle();
  return ContextHandle(context);
}

// A dense n x n matrix and its direct linear solver, as CVODE's Newton and
// IDA both use. Returns what failed, or an empty string.
inline std::string MakeDenseLinearSolver(sunindextype n, N_Vector y, SUNContext context,
                                         MatrixHandle* matrix, LinearSolverHandle* solver) {
  matrix->reset(SUNDenseMatrix(n, n, context));
  if (!*matrix) return "SUNDenseMatrix failed";
  solver->reset(SUNLinSol_Dense(y, matrix->get(), context));
  if (!*solver) return "SUNLinSol_Dense failed";
  return "";
}

}  // namespace rmhb::integrators::detail

#endif  // RMHB_INTEGRATORS_DETAIL_SUNDIALS_HANDLES_H_

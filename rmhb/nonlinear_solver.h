#ifndef RMHB_NONLINEAR_SOLVER_H_
#define RMHB_NONLINEAR_SOLVER_H_

// Solvers for F(x) = 0 with F: R^n -> R^m, m >= n. Harmonic balance of a
// conservative system is naturally overdetermined by one (an amplitude and a
// phase condition for one unknown frequency, consistent because energy is
// conserved), and its square Jacobian is singular (METHOD.md s.5), so every
// method here accepts non-square and rank-deficient problems.
//  - Newton: LU when square, least squares (Gauss-Newton, pivoted QR)
//    otherwise, with a backtracking line search on |F|^2.
//  - Levenberg-Marquardt: (J'J + lambda diag(J'J)) dx = -J'F, lambda x10 on a
//    rejected step and /10 on an accepted one (Marquardt 1963).
//  - Tikhonov: (J'J + mu I) dx = -J'F with mu tied to |F| so that the
//    regularisation vanishes at the solution and convergence stays fast.
// A solve never throws because it did not converge: that is a status.

#include <string>
#include <vector>

#include <Eigen/Dense>

namespace rmhb {

class NonlinearProblem {
 public:
  virtual ~NonlinearProblem() = default;
  virtual int num_unknowns() const = 0;
  virtual int num_residuals() const = 0;
  // Fills the residual and, when `jacobian` is not null, dF/dx. Returns false
  // when the point is not admissible (non-finite values).
  virtual bool Evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* residual,
                        Eigen::MatrixXd* jacobian) = 0;
};

enum class SolverMethod { kAuto, kNewton, kLevenbergMarquardt, kTikhonov };
const char* ToString(SolverMethod method);
// "auto", "newton", "lm", "tikhonov"; throws std::invalid_argument otherwise.
SolverMethod ParseSolverMethod(const std::string& name);

struct SolverOptions {
  // kAuto: Newton (Gauss-Newton if overdetermined); on failure, Levenberg-
  // Marquardt from the same starting point.
  SolverMethod method = SolverMethod::kAuto;
  int max_iterations = 100;
  // Converged when max|F| <= residual_tolerance, or when the step is below
  // step_tolerance * (1 + max|x|) (round-off floor of an inconsistent
  // least-squares problem).
  double residual_tolerance = 1e-15;
  double step_tolerance = 1e-14;
  // A step-size stop with max|F| above this is a stationary point of |F|^2
  // that is not a solution (or a hopelessly truncated one): not converged.
  double acceptable_residual = 1e-6;
  double initial_lambda = 1e-4;
  double lambda_factor = 10.0;
  double tikhonov_factor = 1e-3;  // mu = factor * |F|
  // Newton keeps its factorised Jacobian while each step shrinks max|F| by at
  // least this factor (chord steps: O(n^2) instead of O(n^3) per iteration).
  // 0 disables reuse.
  double chord_contraction = 0.05;
  // Wall-clock budget of the whole solve in seconds (kAuto: Newton and the
  // fallback together); 0 for none. Running out is kNoConvergence with a
  // message that says so. A bound on what a failing solve can cost: every
  // regularised iteration is O(n^3), and a Levenberg-Marquardt fallback that
  // crawls from a poor guess on a thousand unknowns takes minutes.
  double max_seconds = 0;
  // kAuto: iteration cap of the Levenberg-Marquardt fallback (at most
  // max_iterations). It rescues guesses that are near a solution but outside
  // Newton's region; one that needs more is better restarted from a better
  // guess than crawled to.
  int fallback_max_iterations = 50;
  bool estimate_condition = false;  // costs one SVD of the final Jacobian
  bool verbose = false;
  std::string IsValid() const;  // empty when valid, otherwise what is wrong
};

enum class SolverStatus { kConverged, kNoConvergence, kFailure, kInvalidInput };
const char* ToString(SolverStatus status);

struct SolverSummary {
  SolverStatus status = SolverStatus::kInvalidInput;
  SolverMethod method = SolverMethod::kAuto;
  std::string message;
  int iterations = 0;
  int evaluations = 0;
  double initial_residual = 0;  // max|F|
  double final_residual = 0;
  double final_step = 0;
  double condition_estimate = 0;  // 0 when not estimated
  // Cheap reciprocal condition of the last factorised Newton Jacobian, free
  // with every Newton solve (O(n^2) on top of the O(n^3) factorisation): the
  // LU's 1-norm estimate (Hager/Higham) when square, min/max |R_ii| of the QR
  // when overdetermined (a rough lower bound on the true 1/cond). The
  // regularised methods factorise their final J once for it. 0 when not
  // computed (the solve failed before a Jacobian). Near 1e-16 the last digits of the
  // solution are not to be trusted whatever the residual says.
  double reciprocal_condition = 0;
  double seconds = 0;
  std::vector<double> residual_history;
  int num_unknowns = 0;
  int num_residuals = 0;

  bool converged() const { return status == SolverStatus::kConverged; }
  std::string BriefReport() const;
  std::string FullReport() const;
};

// Solves in place from the initial guess in *x.
SolverSummary SolveNonlinear(NonlinearProblem& problem, Eigen::VectorXd* x,
                             const SolverOptions& options = {});

}  // namespace rmhb

#endif  // RMHB_NONLINEAR_SOLVER_H_

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
//
// Scaling (SolverOptions::scaling, kEquilibrate by default): every method
// works on the equilibrated system J_s = D_r J D_c (rmhb/equilibration.h:
// Ruiz, power-of-two factors), recomputed whenever the Jacobian is
// refactorised: Newton solves J_s y = -D_r F and steps dx = D_c y;
// Gauss-Newton's QR, Levenberg-Marquardt and Tikhonov do the same with J_s.
// For a square system the Newton step is unchanged (up to round-off).
// What changes is what the tolerances mean: they are tested on the scaled
// residual max|D_r F| and the scaled step max|D_c^-1 dx| against
// max|D_c^-1 x|, quantities that do not depend on the units the model is
// written in. A MEMS resonator in SI units (metres ~1e-6, newtons ~1e-9)
// then converges to the same relative accuracy as its nondimensional form,
// where the absolute max|F| <= 1e-15 was met at a relative error of 1e-9.
// Deuflhard's monotonicity test stays in the model's units (see the .cc).
// Overdetermined systems keep their row weights (only D_c enters the QR and
// the regularised normal equations): a truncated conservative harmonic
// balance is consistent only in the limit, and row weights would move its
// least-squares solution. kNone is the old behaviour (D_r = D_c = I):
// absolute tests on max|F| and on the step. On singular square Jacobians
// (the paper's scheme 2) the two differ in whether Newton stalls at 1e-10
// or creeps to round-off, as do two LU implementations: such a Jacobian has
// no well-defined Newton step, L-M and Tikhonov are the methods for it.

#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

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

  // Large problems (METHOD.md s.17), optional: a problem that can keep its
  // linearisation about x offers exact Jacobian-vector products and its
  // Jacobian as a sparse matrix, exact or coarsened, so that Newton needs
  // no dense J (LinearSolver::kSparse, kKrylov).
  virtual bool HasLinearization() const { return false; }
  // F(x), keeping the linearisation about x for the two calls below (a
  // later Evaluate does not disturb it). False when not admissible.
  virtual bool Linearize(const Eigen::VectorXd& x, Eigen::VectorXd* residual);
  // J v at the kept linearisation.
  virtual void ApplyJacobian(const Eigen::VectorXd& v, Eigen::VectorXd* product);
  // J at the kept linearisation; with coupling < 1 a coarsened J that keeps
  // the full coupling only among the first `coupling` fraction of each
  // unknown's modes (the rest: their diagonal blocks), the Krylov
  // preconditioner. coupling = 1 is the exact J.
  virtual void SparseJacobian(double coupling, Eigen::SparseMatrix<double>* jacobian);
  // Fraction of J's entries that can be nonzero (structure only, without
  // assembling J): what the automatic choice of linear solver reads.
  virtual double JacobianDensity() const { return 1; }
};

enum class SolverMethod { kAuto, kNewton, kLevenbergMarquardt, kTikhonov };
const char* ToString(SolverMethod method);
// "auto", "newton", "lm", "tikhonov"; throws std::invalid_argument otherwise.
SolverMethod ParseSolverMethod(const std::string& name);

enum class Scaling { kNone, kEquilibrate };
const char* ToString(Scaling scaling);
// "none", "equilibrate"; throws std::invalid_argument otherwise.
Scaling ParseScaling(const std::string& name);

// How Newton solves J dx = -F (METHOD.md s.17). kDense: LAPACK LU (QR when
// overdetermined); kSparse: the exact sparse J by UMFPACK; kKrylov: GMRES
// (Eigen) on exact Jacobian-vector products, preconditioned by the UMFPACK
// LU of a coarsened J. kSparse and kKrylov need a square system and a
// problem with HasLinearization(). kAuto: dense up to
// SolverOptions::dense_limit unknowns (and always for a non-square system or
// a problem without the large-problem interface); above it Krylov, which
// the README's table shows fastest at every size on both a dense-coupled and
// a block-tridiagonal J. Should Newton-Krylov fail where J is block-sparse
// (JacobianDensity() <= sparse_density), Newton runs again with the sparse
// LU, which does not depend on how good the preconditioner is. The
// regularised methods (lm, tikhonov) are always dense.
enum class LinearSolver { kAuto, kDense, kSparse, kKrylov };
const char* ToString(LinearSolver solver);
// "auto", "dense", "sparse", "krylov"; throws std::invalid_argument otherwise.
LinearSolver ParseLinearSolver(const std::string& name);

struct SolverOptions {
  // kAuto: Newton (Gauss-Newton if overdetermined); on failure, Levenberg-
  // Marquardt from the same starting point.
  SolverMethod method = SolverMethod::kAuto;
  int max_iterations = 100;
  // Equilibrate rows and columns (see the top of this file), or not.
  Scaling scaling = Scaling::kEquilibrate;
  // kEquilibrate: converged when max|D_r F| <= residual_tolerance * X, or
  // when the scaled step max|D_c^-1 dx| <= step_tolerance * X (round-off
  // floor of an inconsistent least-squares problem), with X = max|D_c^-1 x|
  // (or of the initial guess, if larger; 1 if both are 0). J cannot tell
  // the units of F from those of x: a change x -> a x, F -> b F scales J by
  // b/a, which Ruiz splits evenly between D_r and D_c, so that max|D_r F|,
  // max|D_c^-1 dx| and X all scale by sqrt(a b) and the tests are unit
  // invariant only as ratios. After equilibration the entries of D_r J D_c
  // are O(1), so residual_tolerance is a relative residual,
  // |J_s||y| against |J_s y - b|, and bounds the relative error of the
  // solution by about residual_tolerance / rcond(J_s).
  // kNone: max|F| <= residual_tolerance (absolute), step below
  // step_tolerance * (1 + max|x|): the old behaviour.
  double residual_tolerance = 1e-15;
  double step_tolerance = 1e-14;
  // A step-size stop with max|D_r F| above this (times X, as above) is a
  // stationary point of |F|^2 that is not a solution (or a hopelessly
  // truncated one): not converged.
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
  // Newton (and Gauss-Newton) gives up, kNoConvergence, when max|F| has not
  // fallen below half its best value for this many iterations; 0: never.
  // From random starts a damped Newton that misses every solution settles
  // into a cycle (the Duffing Monte Carlo's: max|F| between 3.6 and 5.1 for
  // the remaining 60-90 iterations), while the converging runs of the same
  // 10^4 starts halved it at least every 29 iterations. The Monte Carlo sets
  // 20 (MonteCarloOptions::newton_stall_iterations).
  int newton_stall_iterations = 0;
  // The linear solver of Newton's steps and what kAuto decides on (see
  // LinearSolver above; the thresholds are where the README's table of time
  // against unknowns has them cross).
  LinearSolver linear_solver = LinearSolver::kAuto;
  int dense_limit = 800;
  double sparse_density = 0.25;
  // kKrylov: the preconditioner couples this fraction of the modes fully
  // (the rest by their diagonal blocks); GMRES stops at this relative
  // (preconditioned) residual or after this many iterations per step.
  // At most krylov_max_coupled unknowns are coupled: the LU of a dense
  // coupled block grows as its cube, the GMRES iterations far slower.
  double krylov_coupling = 0.0625;
  int krylov_max_coupled = 1000;
  double krylov_tolerance = 1e-12;
  int krylov_max_iterations = 300;
  // Every Newton step uses the current linearisation's exact products; the
  // preconditioner (its assembly and LU) is rebuilt only after a GMRES
  // solve that needed more than this many iterations.
  int krylov_rebuild_iterations = 40;
  bool estimate_condition = false;  // costs one SVD of the final Jacobian
  // The summary's reciprocal_condition and scaled_reciprocal_condition of
  // the final Jacobian: a dozen O(n^2) solves, and for the regularised
  // methods one more factorisation. A census of random starts that reads
  // neither turns them off (0: not computed); at 7 unknowns they were 6 %
  // of its solves.
  bool report_condition = true;
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
  double initial_residual = 0;  // max|F|, unscaled, in the model's units
  double final_residual = 0;
  // max|D_r F| at the end: what residual_tolerance was tested on (equal to
  // final_residual with Scaling::kNone).
  double scaled_residual = 0;
  double final_step = 0;
  double condition_estimate = 0;  // 0 when not estimated
  // Cheap reciprocal condition of the last factorised Newton Jacobian, free
  // with every Newton solve (O(n^2) on top of the O(n^3) factorisation): the
  // LU's 1-norm estimate (Hager/Higham) when square, min/max |R_ii| of the QR
  // when overdetermined (a rough lower bound on the true 1/cond). The
  // regularised methods factorise their final J once for it. 0 when not
  // computed (the solve failed before a Jacobian). Near 1e-16 the last digits of the
  // solution are not to be trusted whatever the residual says.
  // With equilibration this stays the estimate for the UNSCALED J, from the
  // one factorisation of J_s = D_r J D_c: when square, Hager/Higham's 1-norm
  // estimator run on J^-1 = D_c J_s^-1 D_r (a few O(n^2) solves with the
  // scaled LU) over |J|_1; when overdetermined, min/max |R_ii / c_i| with
  // R from the QR of J_s, i.e. the diagonal ratio of R D_c^-1, the R factor
  // of the row-weighted D_r J (the row weights are not undone: that would
  // take a second QR).
  double reciprocal_condition = 0;
  // The same estimate for the scaled J_s = D_r J D_c that the solver
  // factorised (Eigen's LU rcond, or min/max |R_ii|): how much of the
  // ill-conditioning was units, not the problem. Equal to
  // reciprocal_condition with Scaling::kNone.
  double scaled_reciprocal_condition = 0;
  Scaling scaling = Scaling::kNone;
  double seconds = 0;
  std::vector<double> residual_history;
  int num_unknowns = 0;
  int num_residuals = 0;
  // The linear solver Newton used (never kAuto after a solve; kDense for
  // the regularised methods), the GMRES iterations over all steps (kKrylov),
  // and the process's peak resident memory at the end of the solve (bytes,
  // getrusage; 0 where unknown).
  LinearSolver linear_solver = LinearSolver::kDense;
  int linear_iterations = 0;
  double peak_memory_bytes = 0;

  bool converged() const { return status == SolverStatus::kConverged; }
  std::string BriefReport() const;
  std::string FullReport() const;
};

// What kAuto (or the option given) picks for this problem.
LinearSolver ChooseLinearSolver(const NonlinearProblem& problem, const SolverOptions& options);

// The process's peak resident memory so far, in bytes (0 where unknown).
double PeakMemoryBytes();

// Solves in place from the initial guess in *x.
SolverSummary SolveNonlinear(NonlinearProblem& problem, Eigen::VectorXd* x,
                             const SolverOptions& options = {});

}  // namespace rmhb

#endif  // RMHB_NONLINEAR_SOLVER_H_

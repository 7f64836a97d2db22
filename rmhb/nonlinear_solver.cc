#include "rmhb/nonlinear_solver.h"

#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <Eigen/UmfPackSupport>
#include <unsupported/Eigen/IterativeSolvers>

#include "rmhb/dense_factorization.h"
#include "rmhb/equilibration.h"
#include "rmhb/internal/triangular_solve.h"

namespace rmhb {
namespace krylov {
class ScaledJacobian;
}  // namespace krylov
}  // namespace rmhb

template <>
struct Eigen::internal::traits<rmhb::krylov::ScaledJacobian>
    : public Eigen::internal::traits<Eigen::SparseMatrix<double>> {};

namespace rmhb {
namespace krylov {

// The Newton matrix J_s = D_r J D_c as a matrix-free operator for Eigen's
// GMRES: every product is one NonlinearProblem::ApplyJacobian (for the
// harmonic balance, a few FFTs: O(K log K), METHOD.md s.17). The
// boilerplate is Eigen's documented way to give its iterative solvers a
// matrix-free operator ("Matrix-free solvers" in Eigen's manual).
class ScaledJacobian : public Eigen::EigenBase<ScaledJacobian> {
 public:
  using Scalar = double;
  using RealScalar = double;
  using StorageIndex = int;
  enum { ColsAtCompileTime = Eigen::Dynamic, MaxColsAtCompileTime = Eigen::Dynamic, IsRowMajor = false };

  ScaledJacobian(NonlinearProblem& problem, const Eigen::VectorXd& row, const Eigen::VectorXd& column)
      : problem_(&problem), row_(&row), column_(&column) {}
  Eigen::Index rows() const { return row_->size(); }
  Eigen::Index cols() const { return column_->size(); }
  template <class Rhs>
  Eigen::Product<ScaledJacobian, Rhs, Eigen::AliasFreeProduct> operator*(
      const Eigen::MatrixBase<Rhs>& x) const {
    return Eigen::Product<ScaledJacobian, Rhs, Eigen::AliasFreeProduct>(*this, x.derived());
  }
  void Apply(const Eigen::VectorXd& y, Eigen::VectorXd* out) const {
    problem_->ApplyJacobian(column_->cwiseProduct(y), out);
    *out = row_->cwiseProduct(*out);
  }

 private:
  NonlinearProblem* problem_;
  const Eigen::VectorXd* row_;
  const Eigen::VectorXd* column_;
};

// The preconditioner: the UMFPACK LU of the scaled, coarsened Jacobian,
// factorised by the solver before GMRES starts (compute() has nothing to do).
class LuPreconditioner {
 public:
  using Lu = Eigen::UmfPackLU<Eigen::SparseMatrix<double>>;
  LuPreconditioner() = default;
  void set(const Lu* lu) { lu_ = lu; }
  template <class MatrixType>
  LuPreconditioner& compute(const MatrixType&) { return *this; }
  template <class MatrixType>
  LuPreconditioner& analyzePattern(const MatrixType&) { return *this; }
  template <class MatrixType>
  LuPreconditioner& factorize(const MatrixType&) { return *this; }
  template <class Rhs>
  Eigen::VectorXd solve(const Eigen::MatrixBase<Rhs>& b) const { return lu_->solve(b.eval()); }
  Eigen::ComputationInfo info() const { return Eigen::Success; }

 private:
  const Lu* lu_ = nullptr;
};

}  // namespace krylov
}  // namespace rmhb

namespace Eigen {
namespace internal {
template <class Rhs>
struct generic_product_impl<rmhb::krylov::ScaledJacobian, Rhs, SparseShape, DenseShape, GemvProduct>
    : generic_product_impl_base<rmhb::krylov::ScaledJacobian, Rhs,
                                generic_product_impl<rmhb::krylov::ScaledJacobian, Rhs>> {
  template <class Dest>
  static void scaleAndAddTo(Dest& dst, const rmhb::krylov::ScaledJacobian& lhs, const Rhs& rhs,
                            const double& alpha) {
    Eigen::VectorXd product;
    lhs.Apply(rhs, &product);
    dst += alpha * product;
  }
};
}  // namespace internal
}  // namespace Eigen

namespace rmhb {

bool NonlinearProblem::Linearize(const Eigen::VectorXd&, Eigen::VectorXd*) {
  throw std::logic_error("NonlinearProblem::Linearize: this problem has no large-problem interface");
}
void NonlinearProblem::ApplyJacobian(const Eigen::VectorXd&, Eigen::VectorXd*) {
  throw std::logic_error("NonlinearProblem::ApplyJacobian: this problem has no large-problem interface");
}
void NonlinearProblem::SparseJacobian(double, Eigen::SparseMatrix<double>*) {
  throw std::logic_error("NonlinearProblem::SparseJacobian: this problem has no large-problem interface");
}

namespace {

// Eigen's GEMM blocking reads the cache sizes; built with EIGEN_NO_CPUID
// (CMakeLists.txt: CPUID traps under a hypervisor) it would assume
// 32 KB / 256 KB / 2 MB. glibc found the real ones at start-up: the same
// numbers Eigen's own query gives, without its six CPUIDs.
bool TellEigenTheCacheSizes() {
  const long l1 = sysconf(_SC_LEVEL1_DCACHE_SIZE), l2 = sysconf(_SC_LEVEL2_CACHE_SIZE),
             l3 = sysconf(_SC_LEVEL3_CACHE_SIZE);
  if (l1 <= 0 || l2 <= 0) return false;
  Eigen::setCpuCacheSizes(l1, l2, l3 > 0 ? l3 : l2);
  return true;
}

}  // namespace

double PeakMemoryBytes() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return 1024.0 * static_cast<double>(usage.ru_maxrss);  // Linux: KiB
}

namespace {

// The Jacobian in the form the linear solver needs: dense, or (sparse,
// Krylov) the problem's kept linearisation and its sparse J, exact or
// coarsened into the preconditioner. Krylov steps always use the current
// linearisation (exact products: Newton's convergence), but the
// preconditioner is rebuilt only when GMRES needed more than
// krylov_rebuild_iterations with the old one: at a few thousand unknowns
// its LU costs far more than the products (METHOD.md s.17).
class Jacobian {
 public:
  Jacobian(NonlinearProblem& problem, LinearSolver kind, const SolverOptions& options)
      : problem_(problem),
        kind_(kind),
        coupling_(kind != LinearSolver::kKrylov
                      ? 1.0
                      : std::min(options.krylov_coupling,
                                 double(options.krylov_max_coupled) / std::max(1, problem.num_unknowns()))),
        rebuild_iterations_(options.krylov_rebuild_iterations) {}
  LinearSolver kind() const { return kind_; }
  bool dense_form() const { return kind_ == LinearSolver::kDense; }
  // F and J at x; false when either is not finite (or x not admissible).
  bool Evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F) {
    if (dense_form()) {
      dense_.resize(problem_.num_residuals(), problem_.num_unknowns());
      return problem_.Evaluate(x, F, &dense_) && F->allFinite() && dense_.allFinite();
    }
    if (!problem_.Linearize(x, F) || !F->allFinite()) return false;
    if (kind_ == LinearSolver::kKrylov && built_ && last_iterations_ <= rebuild_iterations_) return true;
    problem_.SparseJacobian(coupling_, &sparse_);
    built_ = true;
    ++version_;
    return Eigen::Map<const Eigen::VectorXd>(sparse_.valuePtr(), sparse_.nonZeros()).allFinite();
  }
  // Of the dense J, the sparse J or the preconditioner (kept with it).
  // Into *e, reusing its storage.
  void Equilibrate(Equilibration* e) {
    if (dense_form()) return rmhb::Equilibrate(dense_, e);
    if (scaled_version_ != version_) scaling_ = rmhb::Equilibrate(sparse_), scaled_version_ = version_;
    *e = scaling_;
  }
  const Eigen::MatrixXd& dense() const { return dense_; }
  const Eigen::SparseMatrix<double>& sparse() const { return sparse_; }
  // Changes whenever sparse() does.
  int version() const { return version_; }
  NonlinearProblem& problem() const { return problem_; }
  void ReportIterations(int iterations) { last_iterations_ = iterations; }

 private:
  NonlinearProblem& problem_;
  LinearSolver kind_;
  double coupling_;
  int rebuild_iterations_;
  Eigen::MatrixXd dense_;
  Eigen::SparseMatrix<double> sparse_;
  bool built_ = false;
  int version_ = 0, scaled_version_ = -1, last_iterations_ = 0;
  Equilibration scaling_;
};

// Of an expression too, without a temporary vector: the Monte Carlo's small
// solves called it with products and quotients several times an iteration.
template <class Derived>
double MaxAbs(const Eigen::MatrixBase<Derived>& v) {
  return v.size() ? v.cwiseAbs().maxCoeff() : 0.0;
}

bool Finite(const Eigen::VectorXd& v) { return v.allFinite(); }

double DiagonalRatio(const Eigen::VectorXd& d) {
  const Eigen::VectorXd a = d.cwiseAbs();
  return a.size() && a.maxCoeff() > 0 ? a.minCoeff() / a.maxCoeff() : 0;
}

// *out = diag(row) J diag(column) by plain loops: Eigen's product of two
// diagonals and a dense matrix cost ~1.5 k instructions for the 98
// multiplications of the Monte Carlo's 7 x 7 Jacobians.
void ScaleInto(const Eigen::VectorXd& row, const Eigen::MatrixXd& J, const Eigen::VectorXd& column,
               Eigen::MatrixXd* out) {
  const Eigen::Index m = J.rows();
  out->resize(m, J.cols());
  const double* r = row.data();
  for (Eigen::Index j = 0; j < J.cols(); ++j) {
    const double* a = J.col(j).data();
    double* o = out->col(j).data();
    const double c = column(j);
    for (Eigen::Index i = 0; i < m; ++i) o[i] = r[i] * a[i] * c;
  }
}

// Newton direction of the equilibrated system J_s = D_r J D_c: exact solve
// when square, least squares otherwise; Step returns the scaled step y
// (dx = D_c y). The factorisation is kept so that chord steps can reuse it:
// at a few hundred unknowns the O(n^3) factorisation dominates everything
// else. The scaled matrix is evaluated straight into the factorisation's own
// storage, so scaling costs no extra copy of J.
class NewtonFactorization {
 public:
  explicit NewtonFactorization(const SolverOptions& options) : options_(options) {}
  void Factor(Jacobian& jacobian, const Equilibration& e, bool scaled) {
    kind_ = jacobian.kind();
    if (kind_ == LinearSolver::kDense) return Factor(jacobian.dense(), e, scaled);
    jacobian_ = &jacobian;
    if (jacobian.version() == factored_version_) return;  // the preconditioner is kept
    factored_version_ = jacobian.version();
    // Sparse and Krylov: square systems only (checked before the solve).
    square_ = true;
    row_ = e.row;
    column_ = e.column;
    scaled_ = scaled;
    estimated_ = false;
    const Eigen::SparseMatrix<double>& J = jacobian.sparse();
    // UMFPACK's solves read the matrix again: it lives as long as the LU.
    sparse_scaled_ = row_.asDiagonal() * J * column_.asDiagonal();
    // No iterative refinement: Newton (and GMRES) correct the step anyway,
    // and UMFPACK's default two refinement sweeps tripled the cost of every
    // preconditioner application.
    if (!sparse_lu_) sparse_lu_ = std::make_unique<krylov::LuPreconditioner::Lu>();
    sparse_lu_->umfpackControl()(UMFPACK_IRSTEP) = 0;
    sparse_lu_->compute(sparse_scaled_);
    sparse_failed_ = sparse_lu_->info() != Eigen::Success;
  }
  void Factor(const Eigen::MatrixXd& J, const Equilibration& e, bool scaled) {
    kind_ = LinearSolver::kDense;
    square_ = J.rows() == J.cols();
    // Least squares keeps the model's row weights (see SolverOptions::scaling):
    // the QR of J D_c has J's Q and R D_c, so only the columns are scaled.
    row_ = square_ ? e.row : Eigen::VectorXd::Ones(J.rows());
    column_ = e.column;
    scaled_ = scaled;
    estimated_ = false;
    if (square_) {
      ScaleInto(row_, J, column_, &scratch_);
      lu_.compute(std::move(scratch_));
      // |J|_1 now, while J is at hand, for the estimates a summary asks for.
      if (options_.report_condition) norm_ = J.cwiseAbs().colwise().sum().maxCoeff();
    } else {
      ScaleInto(row_, J, column_, &scratch_);
      qr_.compute(std::move(scratch_));
    }
  }
  // The condition estimates of the last factorisation, computed on first
  // request: the summary reports the final Jacobian's only, so the O(n^2)
  // estimators (dgecon, Hager-Higham: a dozen solves) no longer run at
  // every factorisation of a solve.
  double reciprocal_condition() const { return Estimate(), reciprocal_condition_; }
  double scaled_reciprocal_condition() const { return Estimate(), scaled_reciprocal_condition_; }
  const Eigen::VectorXd& row() const { return row_; }
  const Eigen::VectorXd& column() const { return column_; }
  // The scaled Newton step y for the residual F (unscaled), into *y.
  // Krylov: GMRES to the relative `tolerance` (inexact Newton).
  void Step(const Eigen::VectorXd& F, double tolerance, Eigen::VectorXd* y) {
    b_ = row_.cwiseProduct(F);
    if (kind_ == LinearSolver::kDense && square_) lu_.solve(b_, y);
    else if (kind_ == LinearSolver::kDense) *y = qr_.solve(b_);
    else if (sparse_failed_) y->setConstant(b_.size(), NAN);
    else if (kind_ == LinearSolver::kSparse) *y = sparse_lu_->solve(b_);
    else *y = KrylovSolve(b_, std::max(tolerance, options_.krylov_tolerance));
    *y = -*y;
  }
  // GMRES iterations over every Krylov step so far.
  int linear_iterations() const { return linear_iterations_; }

 private:
  // |J^-1|_1 of the unscaled J by Hager's estimator with Higham's extra
  // alternating vector (Higham, ACM TOMS 14, 1988), through
  // J^-1 = D_c J_s^-1 D_r and J^-T = D_r J_s^-T D_c: a few O(n^2) solves
  // with the LU already made, no second factorisation.
  double InverseOneNorm() const {
    return InverseOneNormEstimate(
        column_.size(),
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
          return column_.cwiseProduct(lu_.solve(row_.cwiseProduct(v)));
        },
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
          return row_.cwiseProduct(lu_.solve_transposed(column_.cwiseProduct(v)));
        });
  }

  // J_s y = b by GMRES (Eigen), preconditioned by the LU of the coarsened
  // J_s, no restart within krylov_max_iterations (the basis costs n words
  // per iteration, far below a dense J). Left preconditioned: the test is
  // on the preconditioned residual.
  Eigen::VectorXd KrylovSolve(const Eigen::VectorXd& b, double tolerance) {
    krylov::ScaledJacobian A(jacobian_->problem(), row_, column_);
    Eigen::GMRES<krylov::ScaledJacobian, krylov::LuPreconditioner> gmres;
    gmres.setTolerance(tolerance);
    gmres.setMaxIterations(options_.krylov_max_iterations);
    gmres.set_restart(options_.krylov_max_iterations);
    gmres.compute(A);
    gmres.preconditioner().set(sparse_lu_.get());
    Eigen::VectorXd y = gmres.solve(b);
    linear_iterations_ += static_cast<int>(gmres.iterations());
    jacobian_->ReportIterations(static_cast<int>(gmres.iterations()));
    return y;
  }

  void Estimate() const {
    if (estimated_) return;
    estimated_ = true;
    // Sparse and Krylov: no estimate (0: not computed).
    if (kind_ != LinearSolver::kDense) return;
    if (square_) {
      scaled_reciprocal_condition_ = lu_.rcond();
      reciprocal_condition_ = scaled_reciprocal_condition_;
      if (scaled_) {
        const double inverse_norm = InverseOneNorm();
        reciprocal_condition_ =
            std::isfinite(inverse_norm) && inverse_norm > 0 && norm_ > 0 ? 1 / (norm_ * inverse_norm) : 0;
      }
    } else {
      const Eigen::VectorXd r = qr_.matrixQR().diagonal();
      scaled_reciprocal_condition_ = DiagonalRatio(r);
      reciprocal_condition_ = DiagonalRatio(r.cwiseQuotient(column_));
    }
  }

  const SolverOptions& options_;
  LinearSolver kind_ = LinearSolver::kDense;
  Eigen::SparseMatrix<double> sparse_scaled_;  // D_r J D_c, sparse J or the preconditioner's
  // Made on the first sparse factorisation: UMFPACK's defaults, read in its
  // constructor, were a first touch of its library in every dense solve.
  std::unique_ptr<krylov::LuPreconditioner::Lu> sparse_lu_;
  bool sparse_failed_ = false;
  Jacobian* jacobian_ = nullptr;  // sparse, Krylov: the products, the preconditioner's age
  int factored_version_ = -1;
  int linear_iterations_ = 0;
  bool square_ = true, scaled_ = false;
  mutable bool estimated_ = false;
  double norm_ = 0;
  Eigen::MatrixXd scratch_;  // J_s before it moves into the factorisation
  mutable double reciprocal_condition_ = 0, scaled_reciprocal_condition_ = 0;
  Eigen::VectorXd row_, column_;
  Eigen::VectorXd b_;  // Step's scaled right-hand side, kept across steps
  DenseLu lu_;  // LAPACK: 1.4-2.4x faster than Eigen's at large n
  DenseQr qr_;
};

// Below this many unknowns the regularised step's normal equations are
// formed and factorised by plain loops: on the Monte Carlo's 7 x 7 systems
// Eigen's blocked product packed both operands first, and a step (copy,
// factorisation, substitutions) cost 4.8 k instructions with Eigen's LDLT,
// 3.4 k with its LLT, 2.3 k with the loops (callgrind).
constexpr Eigen::Index kSmallNormalEquations = 16;

// A = L L' in A's lower triangle (right-looking); false when a pivot is not
// positive (or not finite): A is then not numerically positive definite.
bool SmallCholesky(Eigen::MatrixXd* A) {
  const Eigen::Index n = A->rows();
  for (Eigen::Index k = 0; k < n; ++k) {
    double* ck = A->col(k).data();
    if (!(ck[k] > 0)) return false;
    ck[k] = std::sqrt(ck[k]);
    for (Eigen::Index i = k + 1; i < n; ++i) ck[i] /= ck[k];
    for (Eigen::Index j = k + 1; j < n; ++j) {
      double* cj = A->col(j).data();
      for (Eigen::Index i = j; i < n; ++i) cj[i] -= ck[i] * ck[j];
    }
  }
  return true;
}

// b <- (L L')^-1 b from SmallCholesky's factor.
void SmallCholeskySolve(const Eigen::MatrixXd& L, double* b) {
  internal::LowerSolve(L, internal::Diagonal::kStored, b);
  internal::LowerTransposedSolve(L, internal::Diagonal::kStored, b);
}

// (J'J + D) dx = -J'F; D diagonal. The matrix and the factorisations live
// in `work`, kept across the attempts and iterations of a solve (no
// allocation per attempt). J'J + D is positive definite whenever D > 0 or J
// has full rank: Cholesky without pivoting then, the pivoted LDLT only when
// Cholesky meets a pivot that is not positive (J rank deficient, D ~ 0).
struct RegularizedWork {
  Eigen::MatrixXd A;
  Eigen::LLT<Eigen::MatrixXd> llt;
  Eigen::LDLT<Eigen::MatrixXd> ldlt;
};
void RegularizedStep(const Eigen::MatrixXd& JtJ, const Eigen::VectorXd& JtF,
                     const Eigen::VectorXd& diagonal, RegularizedWork* work, Eigen::VectorXd* y) {
  work->A = JtJ;
  work->A.diagonal() += diagonal;
  if (JtJ.rows() < kSmallNormalEquations) {
    if (SmallCholesky(&work->A)) {
      *y = -JtF;
      SmallCholeskySolve(work->A, y->data());
      return;
    }
    work->A = JtJ;  // the loops overwrote it
    work->A.diagonal() += diagonal;
  } else if (work->llt.compute(work->A).info() == Eigen::Success) {
    *y = -work->llt.solve(JtF);
    return;
  }
  work->ldlt.compute(work->A);
  *y = -work->ldlt.solve(JtF);
}

// J'J of the scaled Jacobian: coefficient-wise for small systems (see
// kSmallNormalEquations), the blocked product above.
void NormalMatrix(const Eigen::MatrixXd& Js, Eigen::MatrixXd* JtJ) {
  if (Js.cols() < kSmallNormalEquations) JtJ->noalias() = Js.transpose().lazyProduct(Js);
  else JtJ->noalias() = Js.transpose() * Js;
}

SolverSummary SolveWith(NonlinearProblem& problem, Eigen::VectorXd* x,
                        const SolverOptions& options);

}  // namespace

const char* ToString(SolverMethod m) {
  switch (m) {
    case SolverMethod::kAuto: return "auto";
    case SolverMethod::kNewton: return "newton";
    case SolverMethod::kLevenbergMarquardt: return "lm";
    case SolverMethod::kTikhonov: return "tikhonov";
  }
  return "?";
}

SolverMethod ParseSolverMethod(const std::string& name) {
  if (name == "auto") return SolverMethod::kAuto;
  if (name == "newton") return SolverMethod::kNewton;
  if (name == "lm") return SolverMethod::kLevenbergMarquardt;
  if (name == "tikhonov") return SolverMethod::kTikhonov;
  throw std::invalid_argument("unknown solver '" + name + "' (expected newton, lm, tikhonov or auto)");
}

const char* ToString(LinearSolver solver) {
  switch (solver) {
    case LinearSolver::kAuto: return "auto";
    case LinearSolver::kDense: return "dense";
    case LinearSolver::kSparse: return "sparse";
    case LinearSolver::kKrylov: return "krylov";
  }
  return "?";
}

LinearSolver ParseLinearSolver(const std::string& name) {
  if (name == "auto") return LinearSolver::kAuto;
  if (name == "dense") return LinearSolver::kDense;
  if (name == "sparse") return LinearSolver::kSparse;
  if (name == "krylov") return LinearSolver::kKrylov;
  throw std::invalid_argument("unknown linear solver '" + name +
                              "' (expected auto, dense, sparse or krylov)");
}

LinearSolver ChooseLinearSolver(const NonlinearProblem& problem, const SolverOptions& options) {
  if (options.linear_solver != LinearSolver::kAuto) return options.linear_solver;
  if (!problem.HasLinearization() || problem.num_residuals() != problem.num_unknowns() ||
      problem.num_unknowns() <= options.dense_limit)
    return LinearSolver::kDense;
  return LinearSolver::kKrylov;
}

const char* ToString(Scaling s) { return s == Scaling::kNone ? "none" : "equilibrate"; }

Scaling ParseScaling(const std::string& name) {
  if (name == "none") return Scaling::kNone;
  if (name == "equilibrate") return Scaling::kEquilibrate;
  throw std::invalid_argument("unknown scaling '" + name + "' (expected equilibrate or none)");
}

const char* ToString(SolverStatus s) {
  switch (s) {
    case SolverStatus::kConverged: return "converged";
    case SolverStatus::kNoConvergence: return "not_converged";
    case SolverStatus::kFailure: return "failed";
    case SolverStatus::kInvalidInput: return "invalid_input";
  }
  return "?";
}

std::string SolverOptions::IsValid() const {
  if (max_iterations < 1) return "max_iterations must be >= 1";
  if (!(residual_tolerance >= 0) || !std::isfinite(residual_tolerance))
    return "residual_tolerance must be finite and >= 0";
  if (!(step_tolerance >= 0) || !std::isfinite(step_tolerance))
    return "step_tolerance must be finite and >= 0";
  if (!(acceptable_residual >= 0)) return "acceptable_residual must be >= 0";
  if (!(initial_lambda > 0) || !std::isfinite(initial_lambda)) return "initial_lambda must be > 0";
  if (!(lambda_factor > 1) || !std::isfinite(lambda_factor)) return "lambda_factor must be > 1";
  if (!(tikhonov_factor > 0) || !std::isfinite(tikhonov_factor)) return "tikhonov_factor must be > 0";
  if (!(max_seconds >= 0) || !std::isfinite(max_seconds))
    return "max_seconds must be finite and >= 0 (0: no limit)";
  if (fallback_max_iterations < 1) return "fallback_max_iterations must be >= 1";
  if (newton_stall_iterations < 0) return "newton_stall_iterations must be >= 0 (0: never)";
  if (dense_limit < 0) return "dense_limit must be >= 0";
  if (!(sparse_density >= 0 && sparse_density <= 1)) return "sparse_density must be in [0, 1]";
  if (!(krylov_coupling > 0 && krylov_coupling <= 1)) return "krylov_coupling must be in (0, 1]";
  if (!(krylov_tolerance > 0 && krylov_tolerance < 1)) return "krylov_tolerance must be in (0, 1)";
  if (krylov_max_iterations < 1) return "krylov_max_iterations must be >= 1";
  if (krylov_rebuild_iterations < 0) return "krylov_rebuild_iterations must be >= 0";
  if (krylov_max_coupled < 1) return "krylov_max_coupled must be >= 1";
  return "";
}

std::string SolverSummary::BriefReport() const {
  std::ostringstream out;
  out << "rmhb solver (" << ToString(method) << "): " << ToString(status) << ", " << iterations
      << " iterations, max|F| " << initial_residual << " -> " << final_residual << ", "
      << seconds * 1e3 << " ms";
  return out.str();
}

std::string SolverSummary::FullReport() const {
  std::ostringstream out;
  out << BriefReport() << "\n";
  out << "  unknowns " << num_unknowns << ", residuals " << num_residuals << ", evaluations "
      << evaluations << ", last step " << final_step << "\n";
  out << "  linear solver " << ToString(linear_solver);
  if (linear_solver == LinearSolver::kKrylov) out << " (" << linear_iterations << " GMRES iterations)";
  if (peak_memory_bytes > 0) out << ", peak memory " << peak_memory_bytes / (1 << 20) << " MiB";
  out << "\n";
  if (scaling == Scaling::kEquilibrate)
    out << "  equilibrated (D_r J D_c, power-of-two Ruiz): scaled max|D_r F| " << scaled_residual
        << "\n";
  if (condition_estimate > 0) out << "  condition estimate of J: " << condition_estimate << "\n";
  if (reciprocal_condition > 0)
    out << "  reciprocal condition of the last factorised J: " << reciprocal_condition << "\n";
  if (scaling == Scaling::kEquilibrate && scaled_reciprocal_condition > 0)
    out << "  reciprocal condition of the equilibrated D_r J D_c: " << scaled_reciprocal_condition
        << "\n";
  if (!message.empty()) out << "  " << message << "\n";
  return out.str();
}

SolverSummary SolveNonlinear(NonlinearProblem& problem, Eigen::VectorXd* x,
                             const SolverOptions& options) {
  static const bool cache_sizes_told = TellEigenTheCacheSizes();
  (void)cache_sizes_told;
  if (options.method != SolverMethod::kAuto) return SolveWith(problem, x, options);
  // Newton (Gauss-Newton when overdetermined) converges quadratically and is
  // the fastest from a good guess; Levenberg-Marquardt is the robust fallback
  // from the same start when it fails.
  const Eigen::VectorXd start = *x;
  SolverOptions o = options;
  o.method = SolverMethod::kNewton;
  SolverSummary newton = SolveWith(problem, x, o);
  if (newton.converged() || newton.status == SolverStatus::kInvalidInput) return newton;
  if (newton.linear_solver == LinearSolver::kKrylov && options.linear_solver == LinearSolver::kAuto &&
      problem.JacobianDensity() <= options.sparse_density &&
      !(options.max_seconds > 0 && newton.seconds >= options.max_seconds)) {
    // A block-sparse J has a direct solver that does not depend on how
    // well the preconditioner approximates it: Newton again with it.
    *x = start;
    o.linear_solver = LinearSolver::kSparse;
    if (options.max_seconds > 0) o.max_seconds = options.max_seconds - newton.seconds;
    SolverSummary sparse = SolveWith(problem, x, o);
    sparse.iterations += newton.iterations;
    sparse.evaluations += newton.evaluations;
    sparse.linear_iterations += newton.linear_iterations;
    sparse.seconds += newton.seconds;
    sparse.message = "Newton-Krylov failed (" + newton.message + "); sparse LU: " +
                     (sparse.message.empty() ? std::string("converged") : sparse.message);
    return sparse;
  }
  if (newton.linear_solver != LinearSolver::kDense) {
    // Levenberg-Marquardt works on a dense J'J: not at this size.
    newton.message = "Newton failed (" + newton.message + "); no Levenberg-Marquardt fallback with the " +
                     ToString(newton.linear_solver) + " linear solver (it needs a dense J)";
    return newton;
  }
  if (options.max_seconds > 0 && newton.seconds >= options.max_seconds) {
    std::ostringstream msg;
    msg << "Newton failed (" << newton.message << "); the time budget of " << options.max_seconds
        << " s is used up, no Levenberg-Marquardt fallback";
    newton.message = msg.str();
    return newton;
  }
  *x = start;
  o.method = SolverMethod::kLevenbergMarquardt;
  o.max_iterations = std::min(options.max_iterations, options.fallback_max_iterations);
  if (options.max_seconds > 0) o.max_seconds = options.max_seconds - newton.seconds;
  SolverSummary lm = SolveWith(problem, x, o);
  lm.iterations += newton.iterations;
  lm.evaluations += newton.evaluations;
  lm.seconds += newton.seconds;
  lm.message = "Newton failed (" + newton.message + "); Levenberg-Marquardt: " +
               (lm.message.empty() ? std::string("converged") : lm.message);
  return lm;
}

namespace {

SolverSummary SolveWith(NonlinearProblem& problem, Eigen::VectorXd* x,
                        const SolverOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SolverSummary s;
  s.num_unknowns = problem.num_unknowns();
  s.num_residuals = problem.num_residuals();
  s.scaling = options.scaling;
  NewtonFactorization factorization(options);
  bool ever_factored = false;
  auto finish = [&](SolverStatus status, std::string message) {
    // The last factorised Jacobian's condition, also when failing.
    if (options.report_condition && ever_factored && s.reciprocal_condition == 0) {
      s.reciprocal_condition = factorization.reciprocal_condition();
      s.scaled_reciprocal_condition = factorization.scaled_reciprocal_condition();
    }
    s.status = status;
    s.message = std::move(message);
    s.linear_iterations = factorization.linear_iterations();
    s.peak_memory_bytes = PeakMemoryBytes();
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return s;
  };
  if (std::string why = options.IsValid(); !why.empty())
    return finish(SolverStatus::kInvalidInput, "invalid options: " + why);
  if (x->size() != s.num_unknowns)
    return finish(SolverStatus::kInvalidInput, "initial guess has the wrong size");
  if (s.num_residuals < s.num_unknowns)
    return finish(SolverStatus::kInvalidInput,
                  "underdetermined: " + std::to_string(s.num_residuals) + " equations for " +
                      std::to_string(s.num_unknowns) + " unknowns");
  // A residual that cannot be evaluated is reported as infinite, never as the
  // default 0 (which would read as an exact solution).
  if (!Finite(*x)) {
    s.initial_residual = s.final_residual = s.scaled_residual = INFINITY;
    return finish(SolverStatus::kInvalidInput, "initial guess is not finite");
  }

  const SolverMethod method = options.method;
  s.method = method;
  // The regularised methods work on J'J: dense.
  s.linear_solver = method == SolverMethod::kNewton ? ChooseLinearSolver(problem, options)
                                                     : LinearSolver::kDense;
  if (s.linear_solver != LinearSolver::kDense) {
    if (!problem.HasLinearization())
      return finish(SolverStatus::kInvalidInput,
                    std::string("linear solver ") + ToString(s.linear_solver) +
                        ": this problem offers no Jacobian products or sparse Jacobian; use dense");
    if (s.num_residuals != s.num_unknowns)
      return finish(SolverStatus::kInvalidInput,
                    std::string("linear solver ") + ToString(s.linear_solver) + " needs a square system (" +
                        std::to_string(s.num_residuals) + " equations for " +
                        std::to_string(s.num_unknowns) + " unknowns); use dense");
  }
  Jacobian J(problem, s.linear_solver, options);

  Eigen::VectorXd F(s.num_residuals), Ftrial(s.num_residuals), xtrial;
  ++s.evaluations;
  if (!J.Evaluate(*x, &F)) {
    s.initial_residual = s.final_residual = s.scaled_residual = INFINITY;
    return finish(SolverStatus::kFailure, "the initial guess gives non-finite residuals");
  }
  // D_r, D_c of the Jacobian last factorised (or, for the regularised
  // methods, of the current one). Every test below is on scaled quantities.
  const bool scaled = options.scaling == Scaling::kEquilibrate;
  Equilibration scaling = IdentityEquilibration(s.num_residuals, s.num_unknowns);
  bool stale = true;  // J changed since `scaling` was computed
  auto rescale = [&] {
    if (scaled && stale) J.Equilibrate(&scaling);
    stale = false;
  };
  auto scaled_norm = [&](const Eigen::VectorXd& residual) {
    return MaxAbs(scaling.row.cwiseProduct(residual));
  };
  auto scaled_size = [&](const Eigen::VectorXd& v) { return MaxAbs(v.cwiseQuotient(scaling.column)); };
  // What the tolerances are relative to. Equilibration fixes how rows and
  // columns compare with each other, but J alone cannot tell the units of F
  // from those of x (x -> a x, F -> b F scales J by b/a; Ruiz splits that
  // evenly, D_r, D_c -> sqrt(a/b) D_r, D_c). max|D_r F| and max|D_c^-1 dx|
  // both scale by sqrt(a b), as does max|D_c^-1 x|: measured against it the
  // tests do not depend on units at all. The starting point's size stands
  // in while x passes through 0, and 1 when both are 0. Unscaled: absolute
  // on F, 1 + max|x| on the step, as before.
  const Eigen::VectorXd x0 = *x;
  auto residual_scale = [&] {
    if (!scaled) return 1.0;
    const double size = std::max(scaled_size(*x), scaled_size(x0));
    return size > 0 ? size : 1.0;
  };
  auto step_scale = [&] { return scaled ? residual_scale() : 1 + MaxAbs(*x); };
  rescale();
  double norm = scaled_norm(F);
  s.initial_residual = s.final_residual = MaxAbs(F);
  s.scaled_residual = norm;
  s.residual_history.push_back(s.final_residual);
  // "max|F| = 3e-9" in messages, with the scaled value the tests used.
  auto residual_text = [&] {
    std::ostringstream out;
    out << "max|F| = " << MaxAbs(F);
    if (scaled) out << " (scaled max|D_r F| = " << norm << ")";
    return out.str();
  };
  double lambda = options.initial_lambda;
  int stalled = 0;
  bool factored = false, chord = false;

  auto out_of_time = [&] {
    return options.max_seconds > 0 &&
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
               options.max_seconds;
  };
  auto time_up = [&] {
    std::ostringstream msg;
    msg << "time budget of " << options.max_seconds << " s used up after " << s.iterations
        << " iterations (" << ToString(method) << "), " << residual_text();
    return finish(SolverStatus::kNoConvergence, msg.str());
  };
  // The regularised methods' matrices and vectors, kept across iterations.
  struct {
    Eigen::MatrixXd Js, JtJ;
    Eigen::VectorXd Fs, JtF, diagonal, weights;
    RegularizedWork work;
  } lm;
  // The step and the Newton corrections: kept across iterations (no
  // allocation per iteration).
  Eigen::VectorXd dx, y, correction;
  double step = 0;  // max|D_c^-1 dx| of the last step
  double best_residual = s.initial_residual;  // max|F|, for newton_stall_iterations
  int since_best = 0;
  for (s.iterations = 1; s.iterations <= options.max_iterations; ++s.iterations) {
    if (norm <= options.residual_tolerance * residual_scale()) {
      --s.iterations;
      break;
    }
    if (out_of_time()) {
      --s.iterations;
      return time_up();
    }
    bool accepted = false;
    double damping = 1.0;
    double trial_norm = norm;
    if (method == SolverMethod::kNewton) {
      if (!factored) {
        rescale();
        norm = scaled_norm(F);
        factorization.Factor(J, scaling, scaled);
        ever_factored = true;
        factored = true;
        chord = false;
      }
      // Inexact Newton (Eisenstat & Walker, SIAM J. Sci. Comput. 17, 1996):
      // a Krylov step need not be more accurate than the residual is small;
      // quadratic convergence survives with a forcing term ~ |F|.
      const double forcing = std::min(1e-4, norm / residual_scale());
      factorization.Step(F, forcing, &y);
      if (!Finite(y)) return finish(SolverStatus::kFailure, "singular Jacobian (Newton step is not finite); try --solver lm");
      // Damping by Deuflhard's natural monotonicity test: accept x + t dx
      // when the simplified Newton correction |J^-1 F(x + t dx)| shrinks by
      // (1 - t/4). It is affine invariant, so the harmonic balance rows that
      // scale with k w do not dominate the test the way they dominate |F|^2,
      // and full steps are taken far earlier; row scaling cannot change it.
      // The corrections are measured in the model's own unknowns, not in
      // D_c^-1 x: in the scaled norm the first step of every order-
      // continuation level of the relativistic oscillator (beta = 0.95) was
      // damped to 1/8, the levels drifted apart, and --tol took 60 s instead
      // of 0.1 s. The full step comes first.
      dx = factorization.column().cwiseProduct(y);
      const double y_norm = dx.norm();
      for (double t = 1.0; t > 1e-4; t *= 0.5) {
        xtrial = *x + t * dx;
        ++s.evaluations;
        if (problem.Evaluate(xtrial, &Ftrial, nullptr) && Finite(Ftrial)) {
          // Only the norm of the simplified correction matters: 1e-3 will do.
          factorization.Step(Ftrial, std::max(forcing, 1e-3), &correction);
          const double simplified = factorization.column().cwiseProduct(correction).norm();
          if (simplified <= (1 - 0.25 * t) * y_norm) {
            accepted = true;
            dx *= t;
            damping = t;
            break;
          }
        }
        if (chord) break;  // a stale Jacobian: refresh rather than backtrack
      }
      if (!accepted && chord) {
        // Retry this iteration with a fresh Jacobian at the same point.
        ++s.evaluations;
        J.Evaluate(*x, &F);
        stale = true;
        factored = false;
        --s.iterations;
        continue;
      }
      if (!accepted) {
        // Near the round-off floor no step decreases |F|: take the full step
        // once if it does not grow the residual much, else stop.
        xtrial = *x + dx;
        ++s.evaluations;
        if (problem.Evaluate(xtrial, &Ftrial, nullptr) && Finite(Ftrial) &&
            scaled_norm(Ftrial) <= 10 * norm + 1e-300)
          accepted = true;
      }

      if (accepted) {
        // Keep the factorisation while it still contracts fast (chord/
        // Shamanskii steps); otherwise refresh the Jacobian at the new point.
        const double trial = scaled_norm(Ftrial);
        const double ratio = trial / std::max(norm, 1e-300);
        // Krylov: a fresh linearisation costs a residual evaluation (its
        // preconditioner is kept, see Jacobian), so every step is a full
        // Newton step.
        if (J.kind() != LinearSolver::kKrylov && ratio < options.chord_contraction &&
            trial > options.residual_tolerance * residual_scale()) {
          chord = true;
        } else {
          factored = false;
        }
      }
    } else {
      // The regularised methods see J afresh every iteration: rescale it.
      rescale();
      norm = scaled_norm(F);
      // Row weights for a square system only, as in NewtonFactorization.
      // Into storage kept across iterations: no allocation per iteration.
      if (s.num_residuals == s.num_unknowns) lm.weights = scaling.row;
      else lm.weights.setOnes(s.num_residuals);
      const Eigen::VectorXd& weights = lm.weights;
      ScaleInto(weights, J.dense(), scaling.column, &lm.Js);
      lm.Fs = weights.cwiseProduct(F);
      NormalMatrix(lm.Js, &lm.JtJ);
      lm.JtF.noalias() = lm.Js.transpose() * lm.Fs;
      const Eigen::MatrixXd& JtJ = lm.JtJ;
      const double F_squared = lm.Fs.squaredNorm();
      for (int attempt = 0; attempt < 30 && !accepted; ++attempt) {
        Eigen::VectorXd& diagonal = lm.diagonal;
        if (method == SolverMethod::kLevenbergMarquardt) {
          diagonal = lambda * JtJ.diagonal().cwiseMax(1e-300);
        } else {
          diagonal = Eigen::VectorXd::Constant(s.num_unknowns,
                                               options.tikhonov_factor * std::sqrt(F_squared) * lambda / options.initial_lambda);
        }
        RegularizedStep(JtJ, lm.JtF, diagonal, &lm.work, &y);
        dx = scaling.column.cwiseProduct(y);
        if (Finite(dx)) {
          xtrial = *x + dx;
          ++s.evaluations;
          if (problem.Evaluate(xtrial, &Ftrial, nullptr) && Finite(Ftrial) &&
              weights.cwiseProduct(Ftrial).squaredNorm() < F_squared) {
            accepted = true;
            lambda = std::max(lambda / options.lambda_factor, 1e-20);
            break;
          }
        }
        lambda *= options.lambda_factor;
        if (lambda > 1e20) break;
        if (out_of_time()) return time_up();
      }
      if (!accepted && MaxAbs(y) <= options.step_tolerance * step_scale() * 1e3) {
        // Already at the floor: no step can reduce |F| in floating point.
        s.final_step = MaxAbs(dx);
        --s.iterations;
        s.scaled_residual = norm;
        if (norm > options.acceptable_residual * residual_scale())
          return finish(SolverStatus::kNoConvergence, "stalled at " + residual_text());
        return finish(SolverStatus::kConverged, "residual at its round-off floor");
      }
    }
    if (!accepted) {
      s.final_step = dx.size() ? MaxAbs(dx) : 0;
      return finish(SolverStatus::kNoConvergence,
                    "no step reduces the residual (" + residual_text() +
                        "); the initial guess may be too far from a solution");
    }
    *x = xtrial;
    if (method == SolverMethod::kNewton && factored) {
      F = Ftrial;
    } else {
      ++s.evaluations;
      stale = true;
      if (!J.Evaluate(*x, &F))
        return finish(SolverStatus::kFailure, "non-finite residual or Jacobian during iteration");
    }
    trial_norm = scaled_norm(F);
    s.final_step = MaxAbs(dx);
    step = scaled_size(dx);
    s.final_residual = MaxAbs(F);
    s.residual_history.push_back(s.final_residual);
    if (options.verbose)
      std::fprintf(stderr, "  iter %3d  max|F| %.3e  scaled %.3e  step %.3e  damping %.3g%s\n",
                   s.iterations, s.final_residual, trial_norm, s.final_step, damping,
                   chord ? " (chord)" : "");
    stalled = trial_norm > 0.5 * norm ? stalled + 1 : 0;
    norm = trial_norm;
    s.scaled_residual = norm;
    if (norm <= options.residual_tolerance * residual_scale()) break;
    const double x_size = step_scale();
    if (step <= options.step_tolerance * x_size) break;
    // Slow progress at a tiny step is a least-squares floor, not a failure.
    if (stalled >= 3 && step <= 1e3 * options.step_tolerance * x_size) break;
    if (method == SolverMethod::kNewton && options.newton_stall_iterations > 0) {
      if (s.final_residual < 0.5 * best_residual) {
        best_residual = s.final_residual;
        since_best = 0;
      } else if (++since_best >= options.newton_stall_iterations) {
        std::ostringstream msg;
        msg << "no progress: max|F| has not halved in " << since_best << " iterations (best " << best_residual
            << "), " << residual_text();
        return finish(SolverStatus::kNoConvergence, msg.str());
      }
    }
  }
  if (ever_factored && options.report_condition) {
    s.reciprocal_condition = factorization.reciprocal_condition();
    s.scaled_reciprocal_condition = factorization.scaled_reciprocal_condition();
  }
  if (options.report_condition && s.reciprocal_condition == 0 && J.dense_form() &&
      (method != SolverMethod::kNewton || s.iterations == 0)) {
    // Converged at the start (a warm start from a lower order), or a
    // regularised method that never factorised J itself: J is the final
    // Jacobian and the summary still owes its condition (one factorisation,
    // the cost of one more iteration). It is what says how near singular
    // the unregularised problem is (METHOD.md s.5).
    rescale();
    factorization.Factor(J, scaling, scaled);
    s.reciprocal_condition = factorization.reciprocal_condition();
    s.scaled_reciprocal_condition = factorization.scaled_reciprocal_condition();
  }
  if (options.estimate_condition && J.dense_form()) {
    if (method == SolverMethod::kNewton && factored) J.Evaluate(*x, &F);
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(J.dense());
    const auto& sv = svd.singularValues();
    s.condition_estimate = sv(sv.size() - 1) > 0 ? sv(0) / sv(sv.size() - 1) : INFINITY;
  }
  s.scaled_residual = norm;
  const double relative_to = residual_scale();
  if (norm > options.residual_tolerance * relative_to && norm > options.acceptable_residual * relative_to)
    return finish(SolverStatus::kNoConvergence,
                  "stalled at " + residual_text() + ": a stationary point of |F|^2 that is not a solution");
  if (s.iterations > options.max_iterations) {
    s.iterations = options.max_iterations;
    return finish(SolverStatus::kNoConvergence, "iteration limit reached with " + residual_text());
  }
  return finish(SolverStatus::kConverged, "");
}

}  // namespace
}  // namespace rmhb

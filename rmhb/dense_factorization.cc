#include "rmhb/dense_factorization.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <complex>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "rmhb/internal/triangular_solve.h"

// LAPACK's Fortran interface as OpenBLAS exports it (32-bit integers on
// Debian). The trailing size_t arguments are gfortran's hidden lengths of the
// character arguments.
extern "C" {
void dgetrf_(const int* m, const int* n, double* a, const int* lda, int* ipiv, int* info);
void dgetrs_(const char* trans, const int* n, const int* nrhs, const double* a, const int* lda,
             const int* ipiv, double* b, const int* ldb, int* info, std::size_t trans_len);
void dgecon_(const char* norm, const int* n, const double* a, const int* lda, const double* anorm,
             double* rcond, double* work, int* iwork, int* info, std::size_t norm_len);
void dgeqrf_(const int* m, const int* n, double* a, const int* lda, double* tau, double* work,
             const int* lwork, int* info);
void dorm2r_(const char* side, const char* trans, const int* m, const int* n, const int* k,
             const double* a, const int* lda, const double* tau, double* c, const int* ldc,
             double* work, int* info, std::size_t side_len, std::size_t trans_len);
void dtrtrs_(const char* uplo, const char* trans, const char* diag, const int* n, const int* nrhs,
             const double* a, const int* lda, double* b, const int* ldb, int* info,
             std::size_t uplo_len, std::size_t trans_len, std::size_t diag_len);
void dggev_(const char* jobvl, const char* jobvr, const int* n, double* a, const int* lda, double* b,
            const int* ldb, double* alphar, double* alphai, double* beta, double* vl, const int* ldvl,
            double* vr, const int* ldvr, double* work, const int* lwork, int* info, std::size_t jobvl_len,
            std::size_t jobvr_len);
int openblas_get_num_threads(void);
void openblas_set_num_threads(int threads);
}

namespace rmhb {
namespace {

std::atomic<int> requested_threads{0};

// OpenBLAS's own count, read before this file ever changes it.
int DefaultThreads() {
  static const int threads = openblas_get_num_threads();
  return threads;
}

// Pins OpenBLAS's thread count for a factorisation with `columns` columns
// (see the header: the count decides the last bits).
void PinThreads(long columns) {
  DefaultThreads();
  openblas_set_num_threads(columns < kMinThreadedDimension ? 1 : DenseFactorizationThreads());
}

int Dimension(long n, const char* what) {
  if (n > std::numeric_limits<int>::max())
    throw std::invalid_argument(std::string(what) + ": dimension " + std::to_string(n) +
                                " exceeds LAPACK's 32-bit integers");
  return static_cast<int>(n);
}

Eigen::VectorXd NotANumber(long n) {
  return Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
}

// P A = L U in place (unit L below the diagonal, U on and above), dgetf2's
// right-looking loop: pivot k is the largest |entry| of column k on and below
// the diagonal, its row swapped into place across the whole matrix. A zero
// pivot leaves its column as it is; true if one was met.
bool UnblockedLu(Eigen::MatrixXd* a, std::vector<int>* pivots) {
  const Eigen::Index n = a->rows();
  bool singular = false;
  for (Eigen::Index k = 0; k < n; ++k) {
    double* ck = a->col(k).data();
    Eigen::Index p = k;
    double largest = std::abs(ck[k]);
    for (Eigen::Index i = k + 1; i < n; ++i)
      if (std::abs(ck[i]) > largest) largest = std::abs(ck[i]), p = i;
    (*pivots)[k] = static_cast<int>(p);
    if (largest == 0) {
      singular = true;
      continue;
    }
    if (p != k) a->row(k).swap(a->row(p));
    const double pivot = ck[k];
    for (Eigen::Index i = k + 1; i < n; ++i) ck[i] /= pivot;
    for (Eigen::Index j = k + 1; j < n; ++j) {
      double* cj = a->col(j).data();
      const double u = cj[k];
      for (Eigen::Index i = k + 1; i < n; ++i) cj[i] -= ck[i] * u;
    }
  }
  return singular;
}

// b <- A^-1 b (or A^-T b) from UnblockedLu's factors of a regular A.
void UnblockedSolve(const Eigen::MatrixXd& lu, const std::vector<int>& pivots, bool transposed, double* b) {
  const Eigen::Index n = lu.rows();
  if (!transposed) {
    for (Eigen::Index k = 0; k < n; ++k) std::swap(b[k], b[pivots[k]]);
    internal::LowerSolve(lu, internal::Diagonal::kUnit, b);  // L y = P b
    for (Eigen::Index k = n - 1; k >= 0; --k) {  // U x = y
      const double* u = lu.col(k).data();
      b[k] /= u[k];
      for (Eigen::Index i = 0; i < k; ++i) b[i] -= u[i] * b[k];
    }
    return;
  }
  // A' = U' L' P: U' z = b, L' w = z (row k of U', L' is column k of U, L).
  for (Eigen::Index k = 0; k < n; ++k) {
    const double* u = lu.col(k).data();
    double sum = b[k];
    for (Eigen::Index i = 0; i < k; ++i) sum -= u[i] * b[i];
    b[k] = sum / u[k];
  }
  internal::LowerTransposedSolve(lu, internal::Diagonal::kUnit, b);
  for (Eigen::Index k = n - 1; k >= 0; --k) std::swap(b[k], b[pivots[k]]);
}

}  // namespace

void SetDenseFactorizationThreads(int threads) {
  if (threads < 0)
    throw std::invalid_argument("SetDenseFactorizationThreads: threads must be >= 0 (0: OpenBLAS's "
                                "default), got " + std::to_string(threads));
  requested_threads = threads;
}

int DenseFactorizationThreads() {
  const int threads = requested_threads;
  return threads > 0 ? threads : DefaultThreads();
}

DenseLu& DenseLu::compute(const Eigen::MatrixXd& A) { return compute(Eigen::MatrixXd(A)); }

DenseLu& DenseLu::compute(Eigen::MatrixXd&& A) {
  if (A.rows() != A.cols())
    throw std::invalid_argument("DenseLu: the matrix is " + std::to_string(A.rows()) + " x " +
                                std::to_string(A.cols()) + ", not square");
  const int n = Dimension(A.rows(), "DenseLu");
  pivots_.assign(n, 0);
  rcond_ = -1;  // estimated on first request
  singular_ = false;
  // dgecon needs the 1-norm of A itself, before it is overwritten.
  norm_ = n ? A.cwiseAbs().colwise().sum().maxCoeff() : 0.0;
  unblocked_ = n > 0 && n <= kMaxUnblockedLuDimension;
  use_small_ = n > kMaxUnblockedLuDimension && n <= kMaxEigenLuDimension;
  if (unblocked_) {
    lu_ = A;  // A is left to the caller, as below; lu_'s storage is reused
    singular_ = UnblockedLu(&lu_, &pivots_);
    return *this;
  }
  if (use_small_) {
    // A is left to the caller (its storage is reused for the next matrix).
    small_.compute(A);
    singular_ = (small_.matrixLU().diagonal().array() == 0).any();
    return *this;
  }
  lu_ = std::move(A);
  if (n == 0) return *this;
  PinThreads(n);
  int info = 0;
  dgetrf_(&n, &n, lu_.data(), &n, pivots_.data(), &info);
  if (info < 0) throw std::logic_error("dgetrf: argument " + std::to_string(-info) + " invalid");
  singular_ = info > 0;
  return *this;
}

double InverseOneNormEstimate(long n, const VectorMap& solve, const VectorMap& solve_transposed) {
  if (n == 0) return 0;
  Eigen::VectorXd x = Eigen::VectorXd::Constant(n, 1.0 / n);
  double estimate = 0;
  Eigen::Index previous = -1;
  for (int k = 0; k < 5; ++k) {
    const Eigen::VectorXd y = solve(x);
    estimate = std::max(estimate, y.lpNorm<1>());
    const Eigen::VectorXd sign = y.unaryExpr([](double v) { return v >= 0 ? 1.0 : -1.0; });
    const Eigen::VectorXd z = solve_transposed(sign);
    Eigen::Index j = 0;
    const double largest = z.cwiseAbs().maxCoeff(&j);
    if (!(largest > z.dot(x)) || j == previous) break;
    x.setZero();
    x(j) = 1;
    previous = j;
  }
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i)
    b(i) = (i % 2 ? -1.0 : 1.0) * (1 + double(i) / std::max<Eigen::Index>(n - 1, 1));
  return std::max(estimate, 2 * solve(b).lpNorm<1>() / (3.0 * n));
}

double DenseLu::rcond() const {
  if (rcond_ >= 0) return rcond_;
  rcond_ = 0;
  const Eigen::MatrixXd& lu = use_small_ ? small_.matrixLU() : lu_;
  const int n = static_cast<int>(lu.rows());
  if (n == 0 || singular_ || !std::isfinite(norm_)) return rcond_;
  if (use_small_ || unblocked_) {
    // Eigen's solves: LAPACK's first call in a fresh process (its code and
    // buffers) cost a small solve more than the estimate (issue 14).
    const double inverse = InverseOneNormEstimate(
        n, [this](const Eigen::VectorXd& v) { return solve(v); },
        [this](const Eigen::VectorXd& v) { return solve_transposed(v); });
    rcond_ = std::isfinite(inverse) && inverse > 0 && norm_ > 0 ? 1 / (norm_ * inverse) : 0;
    return rcond_;
  }
  std::vector<double> work(4 * static_cast<std::size_t>(n));
  std::vector<int> iwork(n);
  int info = 0;
  PinThreads(n);
  dgecon_("1", &n, lu.data(), &n, &norm_, &rcond_, work.data(), iwork.data(), &info, 1);
  if (info != 0) rcond_ = 0;
  return rcond_;
}

Eigen::VectorXd DenseLu::solve(const Eigen::VectorXd& b) const { return Solve(b, "N"); }

void DenseLu::solve(const Eigen::VectorXd& b, Eigen::VectorXd* x) const {
  if (unblocked_ && !singular_ && b.size() == lu_.rows()) {
    *x = b;
    UnblockedSolve(lu_, pivots_, false, x->data());
    return;
  }
  if (!use_small_ || singular_ || b.size() != small_.matrixLU().rows()) {
    *x = Solve(b, "N");
    return;
  }
  *x = small_.solve(b);
}

Eigen::VectorXd DenseLu::solve_transposed(const Eigen::VectorXd& b) const { return Solve(b, "T"); }

Eigen::VectorXd DenseLu::Solve(const Eigen::VectorXd& b, const char* trans) const {
  const int n = static_cast<int>(use_small_ ? small_.matrixLU().rows() : lu_.rows());
  if (b.size() != n)
    throw std::invalid_argument("DenseLu::solve: right-hand side of size " +
                                std::to_string(b.size()) + " for a matrix of " + std::to_string(n));
  if (singular_) return NotANumber(n);
  if (unblocked_) {
    Eigen::VectorXd x = b;
    UnblockedSolve(lu_, pivots_, trans[0] != 'N', x.data());
    return x;
  }
  if (use_small_) return trans[0] == 'N' ? Eigen::VectorXd(small_.solve(b)) : Eigen::VectorXd(small_.transpose().solve(b));
  Eigen::VectorXd x = b;
  if (n == 0) return x;
  PinThreads(n);
  const int one = 1;
  int info = 0;
  dgetrs_(trans, &n, &one, lu_.data(), &n, pivots_.data(), x.data(), &n, &info, 1);
  if (info != 0) throw std::logic_error("dgetrs: argument " + std::to_string(-info) + " invalid");
  return x;
}

DenseQr& DenseQr::compute(const Eigen::MatrixXd& A) { return compute(Eigen::MatrixXd(A)); }

DenseQr& DenseQr::compute(Eigen::MatrixXd&& A) {
  if (A.rows() < A.cols())
    throw std::invalid_argument("DenseQr: the matrix is " + std::to_string(A.rows()) + " x " +
                                std::to_string(A.cols()) + ", fewer rows than columns");
  const int m = Dimension(A.rows(), "DenseQr"), n = Dimension(A.cols(), "DenseQr");
  use_small_ = n > 0 && n <= kMaxEigenQrColumns;
  qr_ = std::move(A);
  tau_.assign(n, 0.0);
  if (n == 0) return *this;
  if (use_small_) {
    // dgeqr2's loop: column i's reflector, applied to the columns right of it.
    Eigen::VectorXd work(n);
    for (int i = 0; i < n; ++i) {
      double beta = 0;
      qr_.col(i).tail(m - i).makeHouseholderInPlace(tau_[i], beta);
      qr_(i, i) = beta;
      qr_.bottomRightCorner(m - i, n - i - 1)
          .applyHouseholderOnTheLeft(qr_.col(i).tail(m - i - 1), tau_[i], work.data());
    }
    return *this;
  }
  PinThreads(n);
  int info = 0, query = -1;
  double size = 0;
  dgeqrf_(&m, &n, qr_.data(), &m, tau_.data(), &size, &query, &info);
  const int lwork = std::max(n, static_cast<int>(size));
  std::vector<double> work(lwork);
  dgeqrf_(&m, &n, qr_.data(), &m, tau_.data(), work.data(), &lwork, &info);
  if (info != 0) throw std::logic_error("dgeqrf: argument " + std::to_string(-info) + " invalid");
  return *this;
}

Eigen::VectorXd DenseQr::solve(const Eigen::VectorXd& b) const {
  const int m = static_cast<int>(qr_.rows()), n = static_cast<int>(qr_.cols());
  if (b.size() != m)
    throw std::invalid_argument("DenseQr::solve: right-hand side of size " +
                                std::to_string(b.size()) + " for a matrix of " + std::to_string(m) +
                                " rows");
  Eigen::VectorXd c = b;
  if (n == 0) return Eigen::VectorXd(0);
  if (use_small_) {
    // Q' b reflector by reflector (H_i = I - tau_i v_i v_i', v_i = [1; below
    // the diagonal of column i]), then R x = (Q' b)(0:n), as dorm2r/dtrtrs.
    for (int i = 0; i < n; ++i) {
      const int below = m - i - 1;
      const double dot = c(i) + qr_.col(i).tail(below).dot(c.tail(below));
      const double scale = tau_[i] * dot;
      c(i) -= scale;
      c.tail(below) -= scale * qr_.col(i).tail(below);
    }
    if ((qr_.diagonal().array() == 0).any()) return NotANumber(n);
    Eigen::VectorXd x = c.head(n);
    qr_.topLeftCorner(n, n).triangularView<Eigen::Upper>().solveInPlace(x);
    return x;
  }
  PinThreads(n);
  // Q' b, then R x = (Q' b)(0:n). One right-hand side: the unblocked
  // dorm2r applies the reflectors one by one (2 m n flops); the blocked
  // dormqr would first build the block reflector (dlarft, O(n^2 nb)) on
  // every call, which was most of a small Newton step's cost.
  const int one = 1;
  int info = 0;
  double work = 0;  // dorm2r needs n_rhs = 1 doubles of work
  dorm2r_("L", "T", &m, &one, &n, qr_.data(), &m, tau_.data(), c.data(), &m, &work, &info, 1, 1);
  if (info != 0) throw std::logic_error("dorm2r: argument " + std::to_string(-info) + " invalid");
  dtrtrs_("U", "N", "N", &n, &one, qr_.data(), &m, c.data(), &m, &info, 1, 1, 1);
  if (info < 0) throw std::logic_error("dtrtrs: argument " + std::to_string(-info) + " invalid");
  if (info > 0) return NotANumber(n);
  return c.head(n);
}

GeneralizedEigen SolveGeneralizedEigen(Eigen::MatrixXd A, Eigen::MatrixXd B) {
  if (A.rows() != A.cols() || B.rows() != A.rows() || B.cols() != A.cols())
    throw std::invalid_argument("generalised eigenproblem: A and B must be square and of one size");
  const int n = Dimension(A.rows(), "generalised eigenproblem");
  // QZ's sweeps are level-1/2 rotations: threads cost more than they gain.
  PinThreads(0);
  std::vector<double> alphar(n), alphai(n), beta(n);
  Eigen::MatrixXd right(n, n);
  int info = 0, lwork = -1, one = 1;
  double query = 0, unused = 0;
  dggev_("N", "V", &n, A.data(), &n, B.data(), &n, alphar.data(), alphai.data(), beta.data(), &unused, &one,
         right.data(), &n, &query, &lwork, &info, 1, 1);
  lwork = std::max(8 * n + 16, static_cast<int>(query));
  std::vector<double> work(lwork);
  dggev_("N", "V", &n, A.data(), &n, B.data(), &n, alphar.data(), alphai.data(), beta.data(), &unused, &one,
         right.data(), &n, work.data(), &lwork, &info, 1, 1);
  if (info != 0)
    throw std::runtime_error("generalised eigenproblem of size " + std::to_string(n) +
                             ": LAPACK's QZ (dggev) failed, info = " + std::to_string(info));
  GeneralizedEigen result{Eigen::VectorXcd(n), Eigen::VectorXd(n), Eigen::MatrixXcd(n, n)};
  const std::complex<double> i(0, 1);
  for (int j = 0; j < n; ++j) {
    result.alphas(j) = {alphar[j], alphai[j]};
    result.betas(j) = beta[j];
    // A complex pair is stored as (Re, Im) in columns j and j + 1 (dggev).
    if (alphai[j] > 0 && j + 1 < n) {
      result.vectors.col(j) = right.col(j) + i * right.col(j + 1);
      result.vectors.col(j + 1) = right.col(j) - i * right.col(j + 1);
    } else if (!(alphai[j] < 0 && j > 0 && alphai[j - 1] > 0)) {
      result.vectors.col(j) = right.col(j).cast<std::complex<double>>();
    }
  }
  return result;
}

}  // namespace rmhb

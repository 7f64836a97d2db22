#ifndef RMHB_DENSE_FACTORIZATION_H_
#define RMHB_DENSE_FACTORIZATION_H_

// Dense LU (partial pivoting) and Householder QR of the Newton Jacobian
// through LAPACK (dgetrf/dgetrs/dgecon, dgeqrf/dorm2r/dtrtrs) from OpenBLAS.
// The factorisation is O(n^3) and dominates every large solve: Van der Pol at
// eps = 50 needs N = 6000, a 12002 x 12002 Jacobian. Measured on this
// project's 2-core machine (tests/benchmarks/dense_factorization_benchmark),
// OpenBLAS's dgetrf is about 1.4x faster than Eigen's PartialPivLU on one
// thread (n = 2000 .. 12000) and 2.2-2.4x on two when the second core is free
// (n = 4000, 8000); on a loaded machine the second thread gains nothing.
//
// The classes keep the calls of Eigen::PartialPivLU and
// Eigen::HouseholderQR that the solver uses (compute, solve, rcond,
// matrixQR), so they replace them one for one; the factors agree with
// Eigen's to round-off, not bit for bit.
//
// Threads and reproducibility: OpenBLAS's factorisations are bit-for-bit
// deterministic for a given thread count, but the last bits change with the
// count. Matrices below kMinThreadedDimension are always factorised on one
// thread (threads cost more than they save there, and small problems give the
// same bits whatever the machine); larger ones use the count set by
// SetDenseFactorizationThreads, by default OpenBLAS's own (the
// OPENBLAS_NUM_THREADS environment variable, else every core). Two runs with
// the same setting on the same machine give identical results.

#include <functional>
#include <vector>

#include <Eigen/Dense>

namespace rmhb {

// Square or tall matrices of fewer columns than this are factorised on one
// thread: at 500 a factorisation takes ~5 ms, where waking threads on a
// loaded machine costs as much as it saves.
constexpr int kMinThreadedDimension = 500;

// Square matrices up to this size (above kMaxUnblockedLuDimension) are
// factorised by Eigen's PartialPivLU in storage kept from one factorisation
// to the next, and solved by its triangular solves: at these sizes
// OpenBLAS's dgetrf/dgetrs spend as much or more (one thread, warm: n = 40:
// 6.6 us against Eigen's 6.4; n = 82: 35 against 31; n = 128: 114 against
// 119), and in a fresh process their first call faults in OpenBLAS's
// buffers and code: the forced Duffing at N = 20 (82 unknowns) paid ~0.1 ms
// of a 0.5 ms first solve for it (issue 14). 14 unknowns (the Monte Carlo's
// Duffing at N = 3): ~1.6 k instructions per dgetrs, more than the solve's
// 400 flops. The 1-norm condition estimate is InverseOneNormEstimate's on
// these factors (dgecon on LAPACK's). The last bits differ from LAPACK's: at 61 unknowns
// the SI-unit MEMS Duffing's CVODE validation error moved from 1.6e-13 to
// 1.9e-12 (CVODE's error, tests/cli/scaling_test.cc holds both with room).
constexpr int kMaxEigenLuDimension = 128;

// Up to this size even Eigen's unblocked LU and triangular solves spend more
// on their block set-up than on the arithmetic: plain loops (dgetf2's
// right-looking elimination, column-oriented substitutions) in kept storage
// instead. Warm, one thread: n = 7: LU 0.29 us against Eigen's 0.45, solve
// 0.12 against 0.18; n = 31: 6.6 against 9.2; n = 51: 21 against 25; n = 64:
// 33 against 29 (Eigen's blocks pay from there).
constexpr int kMaxUnblockedLuDimension = 56;

// Tall matrices up to this many columns are factorised and solved by
// Householder reflectors applied one by one in Eigen (unblocked, as dgeqr2): at these sizes OpenBLAS's dgeqr2/dorm2r call
// dgemv and dger once per column, and that overhead (with its thread checks)
// was 15 % of the relativistic oscillator's solve at N = 55 (58 x 57).
constexpr int kMaxEigenQrColumns = 96;

// Threads for factorisations of kMinThreadedDimension columns and more;
// 0 (the default) leaves OpenBLAS's own choice. Process-wide, like
// OpenBLAS's setting; throws std::invalid_argument when negative.
void SetDenseFactorizationThreads(int threads);
int DenseFactorizationThreads();  // the count in effect for large matrices

// An estimate of ||A^-1||_1 from x -> A^-1 x and x -> A^-T x (Hager and
// Higham's power iteration on the 1-norm with Higham's alternative vector,
// as LAPACK's dlacn2): at most five pairs of solves and one more, O(n^2).
using VectorMap = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;
double InverseOneNormEstimate(long n, const VectorMap& solve, const VectorMap& solve_transposed);

// P A = L U of a square matrix.
class DenseLu {
 public:
  DenseLu& compute(const Eigen::MatrixXd& A);
  // Factorises in A's own storage: no second n x n copy (1 GiB at n = 12000).
  DenseLu& compute(Eigen::MatrixXd&& A);
  // x with A x = b; every entry NaN when A is exactly singular (a zero pivot),
  // which the caller sees as a non-finite step.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // The same into *x (resized only when its size differs): no allocation
  // per solve in a Newton loop of small steps.
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd* x) const;
  // x with A' x = b, from the same factors (condition estimators need it).
  Eigen::VectorXd solve_transposed(const Eigen::VectorXd& b) const;
  // Reciprocal 1-norm condition estimate (Hager/Higham: dgecon on LAPACK's
  // factors, InverseOneNormEstimate on Eigen's); 0 when singular. Computed
  // on the first call after compute (O(n^2), a few solves): a Newton
  // iteration that never asks does not pay for it.
  double rcond() const;
  bool singular() const { return singular_; }

 private:
  Eigen::MatrixXd lu_;
  std::vector<int> pivots_;
  Eigen::PartialPivLU<Eigen::MatrixXd> small_;  // kMaxUnblockedLuDimension < n <= kMaxEigenLuDimension
  bool use_small_ = false;
  bool unblocked_ = false;  // n <= kMaxUnblockedLuDimension: L\U in lu_, by plain loops
  Eigen::VectorXd Solve(const Eigen::VectorXd& b, const char* trans) const;

  mutable double rcond_ = 0;  // -1: not estimated yet
  double norm_ = 0;           // 1-norm of the matrix factorised
  bool singular_ = true;
};

// The generalised eigenproblem A v = lambda B v by LAPACK's QZ (dggev):
// lambda = alphas / betas, beta = 0 for an infinite eigenvalue (B singular),
// the right eigenvectors in the columns of `vectors`. Eigen's RealQZ stops
// without converging on Hill matrices whose B has many zero rows (a recast's
// algebraic auxiliaries, order >= 20: 40+ infinite eigenvalues); dggev
// deflates them. Throws std::runtime_error when QZ fails (info > 0).
struct GeneralizedEigen {
  Eigen::VectorXcd alphas;
  Eigen::VectorXd betas;
  Eigen::MatrixXcd vectors;
};
GeneralizedEigen SolveGeneralizedEigen(Eigen::MatrixXd A, Eigen::MatrixXd B);

// A = Q R of a matrix with at least as many rows as columns.
class DenseQr {
 public:
  DenseQr& compute(const Eigen::MatrixXd& A);
  DenseQr& compute(Eigen::MatrixXd&& A);  // in A's own storage
  // The least-squares solution of min |A x - b|; every entry NaN when R has
  // a zero diagonal entry (rank deficient to the last bit).
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // The same into *x (resized only when its size differs): no allocation
  // per solve in a Newton loop of small steps.
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd* x) const;
  // R in the upper triangle (the Householder vectors below it), as LAPACK
  // and Eigen::HouseholderQR store it.
  const Eigen::MatrixXd& matrixQR() const { return qr_; }

 private:
  Eigen::MatrixXd qr_;
  std::vector<double> tau_;
  bool use_small_ = false;  // columns <= kMaxEigenQrColumns
};

}  // namespace rmhb

#endif  // RMHB_DENSE_FACTORIZATION_H_

#include "rmhb/dense_factorization.h"

#include <cmath>
#include <complex>
#include <cstdlib>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

namespace rmhb {
namespace {

// A random matrix with a dominant diagonal: well conditioned, so the exact
// solution it was built from is the reference to ~1e-13.
Eigen::MatrixXd WellConditioned(int rows, int cols, unsigned seed) {
  std::srand(seed);
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(rows, cols);
  for (int i = 0; i < std::min(rows, cols); ++i) A(i, i) += 2.0 * std::sqrt(double(cols));
  return A;
}

TEST(DenseLu, SolvesToTheExactSolution) {
  for (int n : {1, 7, 64, 300}) {
    const Eigen::MatrixXd A = WellConditioned(n, n, 3 + n);
    const Eigen::VectorXd exact = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
    DenseLu lu;
    lu.compute(A);
    ASSERT_FALSE(lu.singular());
    const Eigen::VectorXd x = lu.solve(A * exact);
    EXPECT_LT((x - exact).cwiseAbs().maxCoeff(), 1e-13) << "n = " << n;
    // Into a vector of another size (resized), then the same one again: the
    // same bits as the returning solve, on both paths.
    Eigen::VectorXd into(1);
    lu.solve(A * exact, &into);
    EXPECT_EQ(into, x) << "n = " << n;
    lu.solve(A * exact, &into);
    EXPECT_EQ(into, x) << "n = " << n;
  }
}

// Every path: the plain loops (n <= kMaxUnblockedLuDimension), Eigen's LU
// (n <= kMaxEigenLuDimension) and LAPACK's.
TEST(DenseLu, TransposedSolveAndMovedMatrixGiveTheExactSolution) {
  for (int n : {14, kMaxUnblockedLuDimension + 8, kMaxEigenLuDimension + 56}) {
    const Eigen::MatrixXd A = WellConditioned(n, n, 5);
    const Eigen::VectorXd exact = Eigen::VectorXd::LinSpaced(n, 2.0, -1.0);
    DenseLu lu;
    lu.compute(Eigen::MatrixXd(A));  // factorised in the moved storage (LAPACK) or a kept copy
    EXPECT_LT((lu.solve_transposed(A.transpose() * exact) - exact).cwiseAbs().maxCoeff(), 1e-13) << n;
    EXPECT_LT((lu.solve(A * exact) - exact).cwiseAbs().maxCoeff(), 1e-13) << n;
    EXPECT_THROW(lu.solve_transposed(Eigen::VectorXd::Ones(n + 1)), std::invalid_argument);
  }
}

// The rows of a diagonally dominant matrix rotated by one: the pivot searches
// swap rows, and both solves must undo the swaps (in opposite orders), on
// every path.
TEST(DenseLu, RowSwapsAreUndoneByBothSolves) {
  for (int n : {2, 7, kMaxUnblockedLuDimension, kMaxUnblockedLuDimension + 1, kMaxEigenLuDimension + 8}) {
    const Eigen::MatrixXd D = WellConditioned(n, n, 13 + n);
    Eigen::MatrixXd A(n, n);
    for (int i = 0; i < n; ++i) A.row(i) = D.row((i + 1) % n);  // column 0's pivot is in the last row
    const Eigen::VectorXd exact = Eigen::VectorXd::LinSpaced(n, 1.5, -0.5);
    DenseLu lu;
    lu.compute(A);
    ASSERT_FALSE(lu.singular()) << n;
    EXPECT_LT((lu.solve(A * exact) - exact).cwiseAbs().maxCoeff(), 1e-13) << n;
    EXPECT_LT((lu.solve_transposed(A.transpose() * exact) - exact).cwiseAbs().maxCoeff(), 1e-13) << n;
    Eigen::VectorXd into;
    lu.solve(A * exact, &into);
    EXPECT_LT((into - exact).cwiseAbs().maxCoeff(), 1e-13) << n;
  }
}

// A factorisation switching between the paths keeps answering for the last matrix.
TEST(DenseLu, SmallAfterLargeAndBackSolveTheLastMatrix) {
  DenseLu lu;
  for (int n : {kMaxEigenLuDimension + 16, 9, kMaxEigenLuDimension + 1, kMaxEigenLuDimension, 12,
                kMaxUnblockedLuDimension + 1}) {
    const Eigen::MatrixXd A = WellConditioned(n, n, 7 + n);
    const Eigen::VectorXd exact = Eigen::VectorXd::LinSpaced(n, -1.0, 3.0);
    lu.compute(A);
    EXPECT_LT((lu.solve(A * exact) - exact).cwiseAbs().maxCoeff(), 1e-13) << n;
    EXPECT_GT(lu.rcond(), 0) << n;
  }
}

// rcond estimates 1/(|A|_1 |A^-1|_1); Hager's estimator is exact or close
// on such matrices, never above the truth.
TEST(DenseLu, ConditionEstimateMatchesTheExplicitInverse) {
  for (double scale : {1.0, 1e-6})
    for (int n : {20, 80, kMaxEigenLuDimension + 20}) {  // loops', Eigen's LU (our estimator), LAPACK's (dgecon)
      Eigen::MatrixXd A = WellConditioned(n, n, 11);
      A.col(5) *= scale;  // ill-conditioned by a factor ~1/scale
      const double exact = 1 / (A.cwiseAbs().colwise().sum().maxCoeff() *
                                A.inverse().cwiseAbs().colwise().sum().maxCoeff());
      DenseLu lu;
      lu.compute(A);
      EXPECT_GE(lu.rcond(), 0.999 * exact) << scale << " " << n;
      EXPECT_LE(lu.rcond(), 3 * exact) << scale << " " << n;
    }
}

TEST(DenseLu, ExactlySingularGivesNaNAndZeroCondition) {
  Eigen::MatrixXd A = WellConditioned(20, 20, 5);
  A.col(7).setZero();
  DenseLu lu;
  lu.compute(A);
  EXPECT_TRUE(lu.singular());
  EXPECT_EQ(lu.rcond(), 0);
  EXPECT_FALSE(lu.solve(Eigen::VectorXd::Ones(20)).allFinite());
}

TEST(DenseLu, RefusesMisuse) {
  DenseLu lu;
  EXPECT_THROW(lu.compute(Eigen::MatrixXd::Identity(3, 4)), std::invalid_argument);
  lu.compute(Eigen::MatrixXd::Identity(3, 3));
  EXPECT_THROW(lu.solve(Eigen::VectorXd::Ones(4)), std::invalid_argument);
  EXPECT_THROW(SetDenseFactorizationThreads(-1), std::invalid_argument);
}

// Above kMinThreadedDimension OpenBLAS threads the factorisation: the same
// count gives the same bits (the CLI's results are reproducible), another
// count the same solution to round-off.
TEST(DenseLu, ThreadedFactorisationIsReproducible) {
  const int n = kMinThreadedDimension + 100;
  const Eigen::MatrixXd A = WellConditioned(n, n, 17);
  const Eigen::VectorXd exact = Eigen::VectorXd::LinSpaced(n, 1.0, -1.0), b = A * exact;
  const int before = DenseFactorizationThreads();
  DenseLu lu;
  SetDenseFactorizationThreads(2);
  const Eigen::VectorXd x1 = lu.compute(A).solve(b), x2 = lu.compute(A).solve(b);
  SetDenseFactorizationThreads(1);
  const Eigen::VectorXd single = lu.compute(A).solve(b);
  SetDenseFactorizationThreads(before);
  EXPECT_EQ(x1, x2);
  EXPECT_LT((x1 - exact).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_LT((single - x1).cwiseAbs().maxCoeff(), 1e-13);
}

// Both paths: Eigen's reflectors up to kMaxEigenQrColumns, LAPACK above.
TEST(DenseQr, ConsistentOverdeterminedSystemGivesTheExactSolution) {
  for (int n : {40, kMaxEigenQrColumns + 20}) {
    const Eigen::MatrixXd A = WellConditioned(n + 1, n, 23);
    const Eigen::VectorXd exact = Eigen::VectorXd::LinSpaced(n, 0.5, -3.0);
    DenseQr qr;
    qr.compute(A);
    EXPECT_LT((qr.solve(A * exact) - exact).cwiseAbs().maxCoeff(), 1e-13) << n << " columns";
  }
}

// An inconsistent right-hand side: the least-squares solution satisfies the
// normal equations A'(A x - b) = 0; |R_ii| are the same as any QR's.
TEST(DenseQr, LeastSquaresMatchesTheNormalEquations) {
  for (int n : {25, kMaxEigenQrColumns + 5}) {
    const Eigen::MatrixXd A = WellConditioned(n + 35, n, 29);
    std::srand(31);
    const Eigen::VectorXd b = Eigen::VectorXd::Random(n + 35);
    DenseQr qr;
    qr.compute(A);
    const Eigen::VectorXd x = qr.solve(b);
    const Eigen::VectorXd normal = (A.transpose() * A).ldlt().solve(A.transpose() * b);
    EXPECT_LT((x - normal).cwiseAbs().maxCoeff(), 1e-13) << n << " columns";
    EXPECT_LT((A.transpose() * (A * x - b)).cwiseAbs().maxCoeff(), 1e-12) << n << " columns";
    const Eigen::HouseholderQR<Eigen::MatrixXd> eigen(A);
    EXPECT_LT((qr.matrixQR().diagonal().cwiseAbs() - eigen.matrixQR().diagonal().cwiseAbs())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-12)
        << n << " columns";
  }
}

TEST(DenseQr, RankDeficientGivesNaNAndMisuseThrows) {
  Eigen::MatrixXd A = WellConditioned(12, 10, 37);
  A.col(3).setZero();
  DenseQr qr;
  qr.compute(A);
  EXPECT_FALSE(qr.solve(Eigen::VectorXd::Ones(12)).allFinite());
  EXPECT_THROW(qr.compute(Eigen::MatrixXd::Ones(3, 4)), std::invalid_argument);
  EXPECT_THROW(qr.solve(Eigen::VectorXd::Ones(3)), std::invalid_argument);
}

// B singular (three zero rows and columns, as a recast's algebraic
// auxiliaries make Hill's B): three infinite eigenvalues (beta = 0) and three
// finite ones, which must be the eigenvalues of the Schur complement
// B11^-1 (A11 - A12 A22^-1 A21), computed independently by Eigen; every
// finite pair (complex ones included) satisfies A v = lambda B v.
TEST(GeneralizedEigen, SingularBGivesTheSchurComplementsEigenvalues) {
  std::srand(7);
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(6, 6) + 3 * Eigen::MatrixXd::Identity(6, 6);
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(6, 6);
  B.topLeftCorner(3, 3) << 1, 0.5, 0, 0, 2, 0, 0.3, 0, 3;
  const GeneralizedEigen qz = SolveGeneralizedEigen(A, B);
  const Eigen::MatrixXd reduced =
      B.topLeftCorner(3, 3).inverse() * (A.topLeftCorner(3, 3) - A.topRightCorner(3, 3) *
                                                                      A.bottomRightCorner(3, 3).inverse() *
                                                                      A.bottomLeftCorner(3, 3));
  const Eigen::VectorXcd expected = Eigen::EigenSolver<Eigen::MatrixXd>(reduced, false).eigenvalues();
  int finite = 0;
  for (int j = 0; j < 6; ++j) {
    if (std::abs(qz.betas(j)) < 1e-12 * std::abs(qz.alphas(j))) continue;
    ++finite;
    const std::complex<double> lambda = qz.alphas(j) / qz.betas(j);
    double nearest = HUGE_VAL;
    for (int k = 0; k < 3; ++k) nearest = std::min(nearest, std::abs(lambda - expected(k)));
    EXPECT_LT(nearest, 1e-12 * (1 + std::abs(lambda))) << lambda;
    const Eigen::VectorXcd v = qz.vectors.col(j);
    const Eigen::VectorXcd r = A.cast<std::complex<double>>() * v - lambda * (B.cast<std::complex<double>>() * v);
    EXPECT_LT(r.norm(), 1e-12 * (1 + std::abs(lambda)) * v.norm()) << lambda;
  }
  EXPECT_EQ(finite, 3);
  EXPECT_THROW(SolveGeneralizedEigen(A, Eigen::MatrixXd::Zero(5, 5)), std::invalid_argument);
}

// A rotation block gives a complex pair: the two vectors are conjugate and
// each satisfies its own eigenvalue.
TEST(GeneralizedEigen, ComplexPairHasConjugateVectors) {
  Eigen::MatrixXd A(3, 3);
  A << 0, -2, 0, 2, 0, 0, 0, 0, 5;
  const GeneralizedEigen qz = SolveGeneralizedEigen(A, Eigen::MatrixXd::Identity(3, 3));
  int pairs = 0;
  for (int j = 0; j < 3; ++j) {
    const std::complex<double> lambda = qz.alphas(j) / qz.betas(j);
    const Eigen::VectorXcd v = qz.vectors.col(j);
    EXPECT_LT((A.cast<std::complex<double>>() * v - lambda * v).norm(), 1e-14 * v.norm()) << lambda;
    if (std::abs(std::abs(lambda.imag()) - 2) < 1e-14) ++pairs;
  }
  EXPECT_EQ(pairs, 2);
}

}  // namespace
}  // namespace rmhb

// Equilibration (rmhb/equilibration.h) and what it does to the nonlinear
// solver: unit-invariant convergence and the condition before and after.

#include "rmhb/equilibration.h"

#include <gtest/gtest.h>

#include <cmath>

#include "rmhb/nonlinear_solver.h"

namespace rmhb {
namespace {

bool PowerOfTwo(double v) {
  int e = 0;
  return v > 0 && std::frexp(v, &e) == 0.5;
}

// diag(10^row_exponents) A diag(10^column_exponents): A in badly chosen units.
Eigen::MatrixXd InUnits(const Eigen::MatrixXd& A, const Eigen::VectorXd& row_exponents,
                        const Eigen::VectorXd& column_exponents) {
  const Eigen::VectorXd P = row_exponents.unaryExpr([](double e) { return std::pow(10.0, e); });
  const Eigen::VectorXd Q = column_exponents.unaryExpr([](double e) { return std::pow(10.0, e); });
  return P.asDiagonal() * A * Q.asDiagonal();
}

Eigen::MatrixXd TestMatrix(int n) {
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = std::sin(1.0 + 3 * i + 7 * j) + (i == j ? 3.0 : 0.0);
  return A;
}

double ReciprocalCondition2(const Eigen::MatrixXd& J) {
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(J).singularValues();
  return sv(sv.size() - 1) / sv(0);
}

TEST(Equilibration, PowerOfTwoFactorsBalanceEveryRowAndColumn) {
  const int n = 8;
  Eigen::VectorXd rows(n), columns(n);
  rows << -9, 3, 0, -7, 5, 1, -2, 8;
  columns << 6, -4, 0, 2, -8, 7, -1, 3;
  const Eigen::MatrixXd J = InUnits(TestMatrix(n), rows, columns);
  const Equilibration e = Equilibrate(J);
  ASSERT_GT(e.sweeps, 0);
  for (int i = 0; i < n; ++i) {
    EXPECT_TRUE(PowerOfTwo(e.row(i))) << e.row(i);
    EXPECT_TRUE(PowerOfTwo(e.column(i))) << e.column(i);
  }
  const Eigen::MatrixXd S = e.row.asDiagonal() * J * e.column.asDiagonal();
  const Eigen::VectorXd row_max = S.cwiseAbs().rowwise().maxCoeff();
  const Eigen::VectorXd column_max = S.cwiseAbs().colwise().maxCoeff().transpose();
  EXPECT_GE(row_max.minCoeff(), 0.5);
  EXPECT_LT(row_max.maxCoeff(), 2.0);
  EXPECT_GE(column_max.minCoeff(), 0.5);
  EXPECT_LT(column_max.maxCoeff(), 2.0);
}

TEST(Equilibration, WellScaledMatrixIsLeftExactlyAlone) {
  Eigen::MatrixXd J = Eigen::MatrixXd::Identity(5, 5);
  J(0, 3) = -0.75;
  const Equilibration e = Equilibrate(J);
  EXPECT_EQ(e.sweeps, 0);
  EXPECT_EQ(e.row, Eigen::VectorXd::Ones(5));
  EXPECT_EQ(e.column, Eigen::VectorXd::Ones(5));
  // A zero row or column keeps its factor 1 rather than dividing by 0.
  J.row(2).setZero();
  const Equilibration z = Equilibrate(J);
  EXPECT_EQ(z.row(2), 1.0);
  EXPECT_TRUE(z.row.allFinite() && z.column.allFinite());
}

// The solver's in-place form: the same factors as a fresh equilibration,
// whatever sizes and factors its storage held before, and that storage
// reused once it has the right size.
TEST(Equilibration, InPlaceGivesTheSameFactorsInItsOwnStorage) {
  Eigen::VectorXd rows(6), columns(6);
  rows << 4, -3, 0, 7, -6, 2;
  columns << -5, 1, 8, 0, -2, 3;
  const Eigen::MatrixXd J = InUnits(TestMatrix(6), rows, columns);
  const Equilibration fresh = Equilibrate(J);
  Equilibration e = Equilibrate(InUnits(TestMatrix(4), rows.head(4), columns.head(4)));
  Equilibrate(J, &e);
  EXPECT_EQ(e.row, fresh.row);
  EXPECT_EQ(e.column, fresh.column);
  EXPECT_EQ(e.sweeps, fresh.sweeps);
  const double* storage = e.row.data();
  Equilibrate(Eigen::MatrixXd(J.transpose()), &e);
  EXPECT_EQ(e.row.data(), storage);
  EXPECT_EQ(e.row, fresh.column);
  EXPECT_EQ(e.column, fresh.row);
}

// G(X) = X^3 + A X - b = 0 with the exact root X* (b made from it), written
// in units: x = Q X, F(x) = P G(Q^-1 x), P and Q spanning 1e-9..1e9 like a
// MEMS model in SI units. `extra_row` appends the consistent equation
// X_0 - X*_0 = 0 (in its own units), an overdetermined system as a
// conservative harmonic balance has.
class InUnitsProblem : public NonlinearProblem {
 public:
  InUnitsProblem(const Eigen::VectorXd& root, const Eigen::VectorXd& row_exponents,
                 const Eigen::VectorXd& column_exponents, bool extra_row)
      : A_(TestMatrix(static_cast<int>(root.size()))), root_(root), extra_row_(extra_row) {
    const int n = static_cast<int>(root.size());
    P_ = row_exponents.head(n + extra_row).unaryExpr([](double e) { return std::pow(10.0, e); });
    Q_ = column_exponents.unaryExpr([](double e) { return std::pow(10.0, e); });
    b_ = root.array().cube().matrix() + A_ * root;
  }
  int num_unknowns() const override { return static_cast<int>(root_.size()); }
  int num_residuals() const override { return num_unknowns() + extra_row_; }
  bool Evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J) override {
    const int n = num_unknowns();
    const Eigen::VectorXd X = x.cwiseQuotient(Q_);
    F->resize(num_residuals());
    F->head(n) = X.array().cube().matrix() + A_ * X - b_;
    if (extra_row_) (*F)(n) = X(0) - root_(0);
    *F = P_.cwiseProduct(*F);
    if (J) {
      Eigen::MatrixXd G = Eigen::MatrixXd::Zero(num_residuals(), n);
      G.topRows(n) = A_;
      G.topRows(n).diagonal() += 3 * X.array().square().matrix();
      if (extra_row_) G(n, 0) = 1;
      *J = P_.asDiagonal() * G * Q_.cwiseInverse().asDiagonal();
    }
    return true;
  }
  Eigen::VectorXd Root() const { return Q_.cwiseProduct(root_); }
  // max_i |x_i - x*_i| / |x*_i|: every unknown to its own relative accuracy.
  double RelativeError(const Eigen::VectorXd& x) const {
    const Eigen::VectorXd r = Root();
    return ((x - r).cwiseQuotient(r)).cwiseAbs().maxCoeff();
  }

 private:
  Eigen::MatrixXd A_;
  Eigen::VectorXd root_, b_, P_, Q_;
  bool extra_row_;
};

struct Units {
  Eigen::VectorXd rows, columns;
};

Units SiUnits() {
  Units u{Eigen::VectorXd(7), Eigen::VectorXd(6)};
  u.rows << -9, -9, -3, -12, 2, -7, -6;
  u.columns << -6, -6, 4, -8, 0, 5;
  return u;
}

Units NoUnits() { return {Eigen::VectorXd::Zero(7), Eigen::VectorXd::Zero(6)}; }

Eigen::VectorXd Root() {
  Eigen::VectorXd r(6);
  r << 0.9, -1.3, 0.45, 2.1, -0.7, 1.6;
  return r;
}

// Each unknown to its relative accuracy, whatever the units, by every
// method, square and overdetermined; the unscaled solver does not get there.
TEST(Equilibration, SolverConvergesToTheSameRelativeAccuracyInAnyUnits) {
  for (bool extra_row : {false, true}) {
    for (SolverMethod method :
         {SolverMethod::kNewton, SolverMethod::kLevenbergMarquardt, SolverMethod::kTikhonov}) {
      // The regularised methods keep an overdetermined system's row weights
      // (see nonlinear_solver.h): in SI-like units they do not converge.
      if (extra_row && method != SolverMethod::kNewton) continue;
      for (const Units& units : {NoUnits(), SiUnits()}) {
        InUnitsProblem problem(Root(), units.rows, units.columns, extra_row);
        Eigen::VectorXd x = 1.1 * problem.Root();  // 10% off in every unknown
        SolverOptions o;
        o.scaling = Scaling::kEquilibrate;
        o.method = method;
        o.max_iterations = 200;
        const SolverSummary s = SolveNonlinear(problem, &x, o);
        const std::string what = std::string(ToString(method)) + (extra_row ? " overdetermined" : " square") +
                                 (units.rows(0) ? " SI" : " nondimensional");
        ASSERT_TRUE(s.converged()) << what << "\n" << s.FullReport();
        EXPECT_LT(problem.RelativeError(x), 1e-13) << what << "\n" << s.FullReport();
      }
    }
  }
  // The old absolute tests: max|F| <= 1e-15 holds early when every
  // residual is in units of 1e-9 or below (a MEMS force balance).
  Units small = SiUnits();
  small.rows.array() -= 11;
  InUnitsProblem problem(Root(), small.rows, small.columns, false);
  Eigen::VectorXd x = 1.1 * problem.Root();
  SolverOptions o;
  o.scaling = Scaling::kNone;
  const SolverSummary s = SolveNonlinear(problem, &x, o);
  EXPECT_GT(problem.RelativeError(x), 1e-10) << s.FullReport();
  Eigen::VectorXd y = 1.1 * problem.Root();
  o.scaling = Scaling::kEquilibrate;
  const SolverSummary scaled = SolveNonlinear(problem, &y, o);
  EXPECT_LT(problem.RelativeError(y), 1e-13) << scaled.FullReport();
}

// Condition before and after: reciprocal_condition is the unscaled J's (as
// the solve summary always meant), scaled_reciprocal_condition that of the
// equilibrated D_r J D_c; each against the SVD of its own matrix, within the
// factor n that separates the 1-norm from the 2-norm condition.
TEST(Equilibration, ConditionBeforeAndAfterScalingMatchTheirSvds) {
  const Units units = SiUnits();
  InUnitsProblem problem(Root(), units.rows, units.columns, false);
  Eigen::VectorXd x = problem.Root();
  x(0) *= 1.01;  // one Newton iteration at least, so the summary factorises J
  SolverOptions o;
  o.scaling = Scaling::kEquilibrate;
  o.method = SolverMethod::kNewton;
  const SolverSummary s = SolveNonlinear(problem, &x, o);
  ASSERT_TRUE(s.converged()) << s.FullReport();
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  problem.Evaluate(x, &F, &J);
  const Equilibration e = Equilibrate(J);
  const double unscaled = ReciprocalCondition2(J);
  const double scaled = ReciprocalCondition2(e.row.asDiagonal() * J * e.column.asDiagonal());
  const double n = 6;
  EXPECT_LT(unscaled, 1e-15);  // the units alone make J hopeless-looking
  EXPECT_GT(scaled, 1e-3);     // the problem itself is well conditioned
  EXPECT_GT(s.reciprocal_condition, unscaled / (10 * n)) << s.FullReport();
  EXPECT_LT(s.reciprocal_condition, unscaled * 10 * n) << s.FullReport();
  EXPECT_GT(s.scaled_reciprocal_condition, scaled / (10 * n)) << s.FullReport();
  EXPECT_LT(s.scaled_reciprocal_condition, scaled * 10 * n) << s.FullReport();
  EXPECT_GE(s.scaled_reciprocal_condition, s.reciprocal_condition);
  // The unscaled estimate from the scaled LU against Eigen's own estimate
  // from an LU of J itself: the same |J^-1|_1, two factorisations.
  const double direct = Eigen::PartialPivLU<Eigen::MatrixXd>(J).rcond();
  EXPECT_GT(s.reciprocal_condition, direct / 10);
  EXPECT_LT(s.reciprocal_condition, direct * 10);
  EXPECT_NE(s.FullReport().find("equilibrated"), std::string::npos) << s.FullReport();

  // Unscaled, the two estimates are one.
  Eigen::VectorXd y = problem.Root();
  y(0) *= 1.01;
  o.scaling = Scaling::kNone;
  const SolverSummary none = SolveNonlinear(problem, &y, o);
  EXPECT_EQ(none.scaled_reciprocal_condition, none.reciprocal_condition);
  EXPECT_GT(none.reciprocal_condition, unscaled / (10 * n));

  // Not asked for (the Monte Carlo's starts): 0, "not computed", and the
  // same solution to the bit.
  Eigen::VectorXd z = problem.Root();
  z(0) *= 1.01;
  o.scaling = Scaling::kEquilibrate;
  o.report_condition = false;
  const SolverSummary quiet = SolveNonlinear(problem, &z, o);
  ASSERT_TRUE(quiet.converged()) << quiet.FullReport();
  EXPECT_EQ(quiet.reciprocal_condition, 0);
  EXPECT_EQ(quiet.scaled_reciprocal_condition, 0);
  EXPECT_EQ(z, x);
}

TEST(Equilibration, ScalingNamesParse) {
  EXPECT_EQ(ParseScaling("none"), Scaling::kNone);
  EXPECT_EQ(ParseScaling("equilibrate"), Scaling::kEquilibrate);
  EXPECT_STREQ(ToString(Scaling::kEquilibrate), "equilibrate");
  EXPECT_EQ(SolverOptions().scaling, Scaling::kEquilibrate);
  EXPECT_THROW(ParseScaling("ruiz"), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb

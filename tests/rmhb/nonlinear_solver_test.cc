#include "rmhb/nonlinear_solver.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

namespace rmhb {
namespace {

// F(x) = (x_i^2 + 1): no real root, so Newton fails and Levenberg-Marquardt
// crawls towards the stationary point x = 0 without ever converging. Each
// evaluation can be made slow to stand in for a large problem.
class NoRoot : public NonlinearProblem {
 public:
  explicit NoRoot(int n, double seconds_per_evaluation = 0)
      : n_(n), delay_(seconds_per_evaluation) {}
  int num_unknowns() const override { return n_; }
  int num_residuals() const override { return n_; }
  bool Evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J) override {
    if (delay_ > 0) std::this_thread::sleep_for(std::chrono::duration<double>(delay_));
    *F = x.array().square() + 1.0;
    if (J) *J = (2 * x).asDiagonal();
    return true;
  }

 private:
  int n_;
  double delay_;
};

TEST(SolverOptions, BudgetsAreValidated) {
  SolverOptions o;
  EXPECT_EQ(o.IsValid(), "");
  o.max_seconds = -1;
  EXPECT_NE(o.IsValid(), "");
  o.max_seconds = 0;
  o.fallback_max_iterations = 0;
  EXPECT_NE(o.IsValid(), "");
}

TEST(NonlinearSolver, FallbackIterationsAreCapped) {
  NoRoot problem(3);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(3, 2.0);
  SolverOptions o;
  o.max_iterations = 1000;
  o.fallback_max_iterations = 7;
  const SolverSummary s = SolveNonlinear(problem, &x, o);
  EXPECT_FALSE(s.converged());
  EXPECT_NE(s.message.find("Levenberg-Marquardt"), std::string::npos) << s.message;
  // Newton's iterations plus at most 7 of the fallback.
  EXPECT_LE(s.iterations, o.max_iterations + 7);
  Eigen::VectorXd y = Eigen::VectorXd::Constant(3, 2.0);
  o.method = SolverMethod::kLevenbergMarquardt;  // explicit LM is not the fallback
  const SolverSummary lm = SolveNonlinear(problem, &y, o);
  EXPECT_GT(lm.iterations, 7);
}

TEST(NonlinearSolver, TimeBudgetStopsAFailingSolveWithAClearMessage) {
  NoRoot problem(2, 0.002);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(2, 2.0);
  SolverOptions o;
  o.max_iterations = 100000;
  o.fallback_max_iterations = 100000;
  o.max_seconds = 0.1;
  const auto start = std::chrono::steady_clock::now();
  const SolverSummary s = SolveNonlinear(problem, &x, o);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(s.status, SolverStatus::kNoConvergence);
  EXPECT_NE(s.message.find("time budget"), std::string::npos) << s.message;
  EXPECT_LT(seconds, 1.0);  // 0.1 s plus one iteration's overshoot, with slack for sanitizers
  for (SolverMethod m : {SolverMethod::kNewton, SolverMethod::kLevenbergMarquardt, SolverMethod::kTikhonov}) {
    Eigen::VectorXd y = Eigen::VectorXd::Constant(2, 2.0);
    o.method = m;
    const SolverSummary t = SolveNonlinear(problem, &y, o);
    EXPECT_FALSE(t.converged()) << ToString(m);
  }
}

}  // namespace
}  // namespace rmhb

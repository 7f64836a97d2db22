#ifndef RMHB_POINTWISE_COLLOCATION_H_
#define RMHB_POINTWISE_COLLOCATION_H_

// Harmonic balance by alternating frequency-time (HB-AFT) applied to the
// ORIGINAL equations, without any recast: an explicit ODE y' = f(t, y) whose
// right-hand side is evaluated pointwise at M oversampled collocation points
// and projected back, E* (w D E Y - f(t_j, E Y)) = 0, plus point conditions.
// The paper's Table 3 compares this with RHB on the recast system: f(y(t))
// of a non-polynomial f has infinitely many harmonics, so the ones above M - N
// alias onto the kept ones for any finite M. The error falls as M grows but
// never vanishes at a finite M; the exact recast (polynomial of degree phi)
// is alias-free at M > (phi+1) N.
//
// The Jacobian of f comes from central differences of the callback at each
// sample (f is a black box here: compiled model equations or a C++ lambda),
// so each Jacobian costs 2 n M evaluations of f. Periodic responses only (one
// base frequency). With an unknown frequency f must be autonomous: the
// sample times t_j = 2 pi j / (M w) move with w, and that dependence is not
// differentiated.

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "rmhb/harmonic_balance.h"
#include "rmhb/harmonic_solution.h"
#include "rmhb/nonlinear_solver.h"
#include "rmhb/point_condition.h"

namespace rmhb {

struct ExplicitOdeProblem {
  std::vector<std::string> names;  // one per state
  std::function<void(double t, const double* y, double* ydot)> rhs;
  double frequency = 1;            // value, or guess if unknown
  bool unknown_frequency = false;
  // On the states: z = y(0), dz = y'(0) (of the harmonic series).
  std::vector<PointCondition> conditions;

  int dimension() const { return static_cast<int>(names.size()); }
};

struct PointwiseCollocationOptions {
  int order = 10;    // N
  int samples = 0;   // M; 0: the smallest power of two >= 4N + 1
  SolverOptions solver;
  std::string IsValid() const;  // empty when valid
};

class PointwiseCollocationResidual : public NonlinearProblem {
 public:
  PointwiseCollocationResidual(const ExplicitOdeProblem& problem, int order, int samples);
  int num_unknowns() const override { return num_unknowns_; }
  int num_residuals() const override { return num_residuals_; }
  bool Evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* residual,
                Eigen::MatrixXd* jacobian) override;

 private:
  const ExplicitOdeProblem& problem_;
  int n_, N_, C_, M_;
  int num_unknowns_, num_residuals_;
  Eigen::MatrixXd E_;      // M x C: [1 cos(k th_j) sin(k th_j) ...]
  Eigen::MatrixXd ED_;     // M x C: d/d(theta) of E
  Eigen::MatrixXd Estar_;  // C x M: the pseudo-inverse, E* E = I
};

// Solves from `guess` (a solution over the ODE's states, any order: it is
// moved onto order options.order). The summary's `solution` holds the
// states; `rule` is reported as kAft and `degree` as 0 (no polynomial).
// Throws std::invalid_argument for invalid options or a guess whose
// variables do not match the states.
HarmonicBalanceSummary SolvePointwiseCollocation(const ExplicitOdeProblem& problem,
                                                 const HarmonicSolution& guess,
                                                 const PointwiseCollocationOptions& options);

}  // namespace rmhb

#endif  // RMHB_POINTWISE_COLLOCATION_H_

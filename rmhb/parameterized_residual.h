#ifndef RMHB_PARAMETERIZED_RESIDUAL_H_
#define RMHB_PARAMETERIZED_RESIDUAL_H_

// The building blocks of continuation (rmhb/continuation.h), for any
// branch-following code that rebuilds its problem as a parameter moves
// (the period-doubled branch and the torus of rmhb/branch_switching.h,
// torus continuation):
//  - ParameterizedResidual: F(x, lambda) of the harmonic balance equations
//    on a fixed basis and sampling, the problem rebuilt from `build` when
//    lambda changes, with [F_x F_lambda] (F_lambda by a forward difference);
//  - BorderedSystem: F = 0 plus one linear condition a . (y - anchor) = step
//    in y = (x, lambda), the pseudo-arclength corrector (a = the tangent) or
//    a fixed lambda (a = e_lambda);
//  - BranchTangent: the unit tangent of the branch at y.

#include <functional>
#include <limits>
#include <memory>
#include <string>

#include <Eigen/Dense>

#include "rmhb/collocation_residual.h"
#include "rmhb/harmonic_balance_problem.h"
#include "rmhb/harmonic_basis.h"
#include "rmhb/nonlinear_solver.h"
#include "rmhb/sampling.h"

namespace rmhb {

// F(x, lambda), rebuilding the problem when lambda changes. Two builds are
// kept: the current value and its finite-difference neighbour, so that a
// Newton iteration costs two builds. With `only_frequencies_change` (the
// builder's promise that build(value) differs from build(first) in its base
// frequencies alone, ContinuationProblem::only_frequencies_change) each of
// the two residuals is built once, and a new value only sets the
// frequencies of its problem from build(value) (METHOD.md s.19).
class ParameterizedResidual {
 public:
  using Build = std::function<HarmonicBalanceProblem(double value)>;
  // Throws std::invalid_argument when the model refuses `first`.
  ParameterizedResidual(std::string parameter, Build build, double first, HarmonicBasis basis,
                        Sampling sampling, bool only_frequencies_change = false);

  int n() const { return n_; }  // unknowns x
  int m() const { return m_; }  // residuals
  // Why the model last refused a value (empty when it has not since the
  // last ClearRefusal).
  const std::string& refusal() const { return refusal_; }
  void ClearRefusal() { refusal_.clear(); }
  const HarmonicBasis& basis() const { return basis_; }
  const Sampling& sampling() const { return sampling_; }

  // The residual at lambda; nullptr when the model refuses the value.
  CollocationResidual* At(double lambda) { return Get(&current_, lambda); }
  // The problem at lambda (after At(lambda) has succeeded).
  const HarmonicBalanceProblem& ProblemAt(double lambda) {
    At(lambda);
    return *current_.problem;
  }

  // F(x, lambda) and, when `jacobian` is given, [F_x F_lambda] (m x (n+1)).
  bool Evaluate(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F, Eigen::MatrixXd* jacobian);

 private:
  struct Built {
    double lambda = std::numeric_limits<double>::quiet_NaN();
    // The residual refers to the problem: destroyed first, built second.
    std::unique_ptr<HarmonicBalanceProblem> problem;
    std::unique_ptr<CollocationResidual> residual;
  };
  CollocationResidual* Get(Built* b, double lambda);
  // The frequencies of build(lambda) into b's problem (only_frequencies_).
  CollocationResidual* Retune(Built* b, double lambda);
  void Refuse(double lambda, const std::exception& e);

  std::string parameter_;
  Build build_;
  bool only_frequencies_ = false;
  HarmonicBasis basis_;
  Sampling sampling_;
  int n_ = -1, m_ = -1;
  std::string refusal_;
  Built current_, neighbour_;
  Eigen::MatrixXd jx_;
  Eigen::VectorXd shifted_f_;
};

// The corrector's system in y = (x, lambda): F(x, lambda) = 0 and one linear
// condition a . (y - anchor) = step. With a the branch tangent this is the
// pseudo-arclength condition; with a = e_lambda it fixes lambda (natural
// continuation, and landing exactly on the end of the range).
class BorderedSystem : public NonlinearProblem {
 public:
  explicit BorderedSystem(ParameterizedResidual* f) : f_(f) {}
  void Aim(const Eigen::VectorXd& anchor, const Eigen::VectorXd& direction, double step) {
    anchor_ = anchor;
    direction_ = direction;
    step_ = step;
  }
  int num_unknowns() const override { return f_->n() + 1; }
  int num_residuals() const override { return f_->m() + 1; }
  bool Evaluate(const Eigen::VectorXd& y, Eigen::VectorXd* residual, Eigen::MatrixXd* jacobian) override;

 private:
  ParameterizedResidual* f_;
  Eigen::VectorXd anchor_, direction_, f_value_;
  Eigen::MatrixXd f_jacobian_;
  double step_ = 0;
};

// The unit tangent of the branch at y, oriented along `previous`: the
// solution of [F_x F_lambda; previous'] t = e_last (least squares when the
// problem is overdetermined), normalised. false when it does not exist.
bool BranchTangent(ParameterizedResidual& f, const Eigen::VectorXd& y, const Eigen::VectorXd& previous,
                   Eigen::VectorXd* tangent);

}  // namespace rmhb

#endif  // RMHB_PARAMETERIZED_RESIDUAL_H_

#ifndef RMHB_POINT_CONDITION_H_
#define RMHB_POINT_CONDITION_H_

// Extra equations on the solution at t = 0: amplitude (theta(0) = a), phase
// (theta'(0) = 0) and the recast's pinning of variables defined through their
// derivative (s(0) = sin(theta(0)), METHOD.md eq. 24). A condition is any
// differentiable function r(z(0), z'(0)); the solver drives r to zero.

#include <functional>
#include <string>

#include <Eigen/Dense>

namespace rmhb {

struct PointCondition {
  std::string description;
  // Returns r; fills dr/dz and dr/dz' (pre-sized, zeroed) when not null.
  std::function<double(const Eigen::VectorXd& z, const Eigen::VectorXd& dz,
                       Eigen::VectorXd* grad_z, Eigen::VectorXd* grad_dz)>
      function;
  // A recast pin (METHOD.md eq. 24): the variable whose constant term it
  // fixes, z_j(0) = its definition at t = 0, or -1. A pin holds at every t
  // for the definition's values, so it is equivariant under every symmetry
  // the definitions have, and implied where a symmetry drops z_j's constant.
  int pinned_variable = -1;

  // z_j(0) = target.
  static PointCondition Value(int variable, double target, std::string description = "");
  // z_j'(0) = target.
  static PointCondition DerivativeValue(int variable, double target,
                                        std::string description = "");
  // z_j(0) = f(z_k(0)), e.g. s(0) = sin(theta(0)).
  static PointCondition Pinned(int variable, int source, std::function<double(double)> f,
                               std::function<double(double)> df, std::string description);
};

}  // namespace rmhb

#endif  // RMHB_POINT_CONDITION_H_

#include "rmhb/point_condition.h"

namespace rmhb {

PointCondition PointCondition::Value(int j, double target, std::string description) {
  if (description.empty())
    description = "z" + std::to_string(j) + "(0) = " + std::to_string(target);
  return {description, [j, target](const Eigen::VectorXd& z, const Eigen::VectorXd&,
                                   Eigen::VectorXd* gz, Eigen::VectorXd*) {
            if (gz) (*gz)(j) = 1.0;
            return z(j) - target;
          }};
}

PointCondition PointCondition::DerivativeValue(int j, double target, std::string description) {
  if (description.empty())
    description = "z" + std::to_string(j) + "'(0) = " + std::to_string(target);
  return {description, [j, target](const Eigen::VectorXd&, const Eigen::VectorXd& dz,
                                   Eigen::VectorXd*, Eigen::VectorXd* gdz) {
            if (gdz) (*gdz)(j) = 1.0;
            return dz(j) - target;
          }};
}

PointCondition PointCondition::Pinned(int j, int k, std::function<double(double)> f,
                                      std::function<double(double)> df, std::string description) {
  return {description, [j, k, f, df](const Eigen::VectorXd& z, const Eigen::VectorXd&,
                                     Eigen::VectorXd* gz, Eigen::VectorXd*) {
            if (gz) {
              (*gz)(j) += 1.0;
              (*gz)(k) -= df(z(k));
            }
            return z(j) - f(z(k));
          },
          j};
}

}  // namespace rmhb

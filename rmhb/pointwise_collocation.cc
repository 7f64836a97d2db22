#include "rmhb/pointwise_collocation.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace rmhb {

std::string PointwiseCollocationOptions::IsValid() const {
  if (order < 1) return "order must be >= 1";
  if (samples != 0 && samples < 2 * order + 1)
    return "samples must be >= 2N+1 = " + std::to_string(2 * order + 1);
  return solver.IsValid();
}

PointwiseCollocationResidual::PointwiseCollocationResidual(const ExplicitOdeProblem& problem,
                                                           int order, int samples)
    : problem_(problem), n_(problem.dimension()), N_(order), C_(2 * order + 1), M_(samples) {
  num_unknowns_ = n_ * C_ + (problem.unknown_frequency ? 1 : 0);
  num_residuals_ = n_ * C_ + static_cast<int>(problem.conditions.size());
  E_.resize(M_, C_);
  ED_.resize(M_, C_);
  for (int j = 0; j < M_; ++j) {
    const double th = 2 * M_PI * j / M_;
    E_(j, 0) = 1;
    ED_(j, 0) = 0;
    for (int k = 1; k <= N_; ++k) {
      E_(j, 2 * k - 1) = std::cos(k * th);
      E_(j, 2 * k) = std::sin(k * th);
      ED_(j, 2 * k - 1) = -k * std::sin(k * th);
      ED_(j, 2 * k) = k * std::cos(k * th);
    }
  }
  Estar_ = (2.0 / M_) * E_.transpose();
  Estar_.row(0) *= 0.5;
}

bool PointwiseCollocationResidual::Evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* residual,
                                            Eigen::MatrixXd* jacobian) {
  const double w = problem_.unknown_frequency ? x(n_ * C_) : problem_.frequency;
  const Eigen::Map<const Eigen::MatrixXd> X(x.data(), C_, n_);  // column i: state i
  const Eigen::MatrixXd Y = E_ * X;                              // M x n samples
  const Eigen::MatrixXd dY = ED_ * X;                            // d/d(theta)
  Eigen::MatrixXd F(M_, n_);
  std::vector<Eigen::MatrixXd> dF;  // per sample, n x n, by central differences
  if (jacobian) dF.assign(M_, Eigen::MatrixXd(n_, n_));
  Eigen::VectorXd y(n_), fp(n_), fm(n_), f(n_);
  for (int j = 0; j < M_; ++j) {
    const double t = 2 * M_PI * j / (M_ * w);
    y = Y.row(j).transpose();
    problem_.rhs(t, y.data(), f.data());
    F.row(j) = f.transpose();
    if (!jacobian) continue;
    for (int m = 0; m < n_; ++m) {
      const double h = 6e-6 * (1 + std::abs(y(m)));  // ~cbrt(eps): central differences
      const double saved = y(m);
      y(m) = saved + h;
      problem_.rhs(t, y.data(), fp.data());
      y(m) = saved - h;
      problem_.rhs(t, y.data(), fm.data());
      y(m) = saved;
      dF[j].col(m) = (fp - fm) / (2 * h);
    }
  }
  residual->resize(num_residuals_);
  for (int i = 0; i < n_; ++i)
    residual->segment(i * C_, C_) = Estar_ * (w * dY.col(i) - F.col(i));
  if (jacobian) {
    jacobian->setZero(num_residuals_, num_unknowns_);
    const Eigen::MatrixXd wD = Estar_ * ED_ * w;  // C x C: w times the derivative matrix
    Eigen::MatrixXd weighted(C_, M_);
    for (int i = 0; i < n_; ++i) {
      jacobian->block(i * C_, i * C_, C_, C_) += wD;
      for (int m = 0; m < n_; ++m) {
        for (int j = 0; j < M_; ++j) weighted.col(j) = Estar_.col(j) * dF[j](i, m);
        jacobian->block(i * C_, m * C_, C_, C_) -= weighted * E_;
      }
      if (problem_.unknown_frequency) jacobian->col(n_ * C_).segment(i * C_, C_) = Estar_ * dY.col(i);
    }
  }
  // Point conditions at t = 0 (theta = 0): y(0) = E row 0, y'(0) = w ED row 0.
  if (!problem_.conditions.empty()) {
    const Eigen::VectorXd z = Y.row(0).transpose();
    const Eigen::VectorXd dz = w * dY.row(0).transpose();
    Eigen::VectorXd gz(n_), gdz(n_);
    int row = n_ * C_;
    for (const auto& cond : problem_.conditions) {
      gz.setZero();
      gdz.setZero();
      (*residual)(row) = cond.function(z, dz, jacobian ? &gz : nullptr, jacobian ? &gdz : nullptr);
      if (jacobian) {
        for (int i = 0; i < n_; ++i) {
          jacobian->block(row, i * C_, 1, C_) += gz(i) * E_.row(0) + gdz(i) * w * ED_.row(0);
          if (problem_.unknown_frequency) (*jacobian)(row, n_ * C_) += gdz(i) * dY(0, i);
        }
      }
      ++row;
    }
  }
  return residual->allFinite() && (!jacobian || jacobian->allFinite());
}

HarmonicBalanceSummary SolvePointwiseCollocation(const ExplicitOdeProblem& problem,
                                                 const HarmonicSolution& guess,
                                                 const PointwiseCollocationOptions& options) {
  const std::string invalid = options.IsValid();
  if (!invalid.empty()) throw std::invalid_argument("pointwise collocation: " + invalid);
  if (!problem.rhs || problem.dimension() < 1)
    throw std::invalid_argument("pointwise collocation: the ODE has no states or no right-hand side");
  if (guess.num_variables() != problem.dimension() || guess.basis().num_bases() != 1)
    throw std::invalid_argument("pointwise collocation: the guess must be periodic over the " +
                                std::to_string(problem.dimension()) + " states");
  const auto start = std::chrono::steady_clock::now();
  const int N = options.order;
  int M = options.samples;
  if (M == 0)
    for (M = 1; M < 4 * N + 1; M *= 2) {
    }
  const HarmonicBasis basis = HarmonicBasis::Periodic(N);
  const HarmonicSolution moved = guess.OnBasis(basis);
  const int C = basis.num_coefficients();
  const int n = problem.dimension();
  Eigen::VectorXd x(n * C + (problem.unknown_frequency ? 1 : 0));
  for (int i = 0; i < n; ++i) x.segment(i * C, C) = moved.coefficients().row(i).transpose();
  if (problem.unknown_frequency) x(n * C) = guess.frequencies()[0];

  PointwiseCollocationResidual residual(problem, N, M);
  HarmonicBalanceSummary summary;
  summary.solver = SolveNonlinear(residual, &x, options.solver);
  const double w = problem.unknown_frequency ? x(n * C) : problem.frequency;
  Eigen::MatrixXd coefficients(n, C);
  for (int i = 0; i < n; ++i) coefficients.row(i) = x.segment(i * C, C).transpose();
  summary.solution = HarmonicSolution(basis, {w}, coefficients, guess.variables());
  summary.sampling = std::to_string(M) + " samples of the original right-hand side (aliases)";
  summary.samples = {M};
  summary.alias_free_samples = {0};
  summary.alias_free = false;
  summary.degree = 0;
  summary.order = N;
  summary.rule = SamplingRule::kAft;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace rmhb

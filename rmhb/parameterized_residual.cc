#include "rmhb/parameterized_residual.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

namespace rmhb {
ParameterizedResidual::ParameterizedResidual(std::string parameter, Build build, double first,
                                             HarmonicBasis basis, Sampling sampling, bool only_frequencies_change)
    : parameter_(std::move(parameter)), build_(std::move(build)), only_frequencies_(only_frequencies_change),
      basis_(std::move(basis)), sampling_(std::move(sampling)) {
  CollocationResidual* r = At(first);
  if (!r)
    throw std::invalid_argument("cannot build the problem at " + parameter_ + " = " + std::to_string(first) +
                                ": " + refusal_);
  n_ = r->num_unknowns();
  m_ = r->num_residuals();
}

bool ParameterizedResidual::Evaluate(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F,
                                     Eigen::MatrixXd* jacobian) {
  CollocationResidual* r = At(lambda);
  if (!r || !r->Evaluate(x, F, jacobian ? &jx_ : nullptr)) return false;
  if (!jacobian) return true;
  jacobian->resize(m_, n_ + 1);
  jacobian->leftCols(n_) = jx_;
  // Forward difference; backward where the model refuses lambda + h (the
  // edge of its domain, e.g. beta -> 1), which is then no refusal. The
  // neighbour's build is reused while its distance from lambda stays within
  // [h/2, 1000 h] (a difference step of at most 1e-4 relative: an O(1e-4)
  // error of one Jacobian column, which slows Newton in no visible digit and
  // moves no fold, whose tangent has a zero lambda component whatever
  // F_lambda is): every build is a model rebuild, dearer than an evaluation,
  // and the corrector's last iterations move lambda by less.
  const std::string refusal = refusal_;
  const double h = 1e-7 * (1 + std::abs(lambda)), kept = neighbour_.lambda - lambda;
  const bool reuse = neighbour_.residual && std::abs(kept) >= 0.5 * h && std::abs(kept) <= 1e3 * h;
  const double forward = reuse ? kept : h;
  for (double spacing : {forward, -h}) {
    CollocationResidual* shifted = Get(&neighbour_, spacing == kept ? neighbour_.lambda : lambda + spacing);
    if (shifted && shifted->Evaluate(x, &shifted_f_, nullptr)) {
      jacobian->col(n_) = (shifted_f_ - *F) / spacing;
      refusal_ = refusal;
      // The other columns are r's J, which its Evaluate returned finite.
      return jacobian->col(n_).allFinite();
    }
  }
  return false;
}

void ParameterizedResidual::Refuse(double lambda, const std::exception& e) {
  // A value outside the model's domain: this step fails, the trace goes on.
  std::ostringstream why;
  why << "at " << parameter_ << " = " << lambda << ": " << e.what();
  refusal_ = why.str();
}

CollocationResidual* ParameterizedResidual::Retune(Built* b, double lambda) {
  b->lambda = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> frequencies;
  try {
    frequencies = build_(lambda).frequencies;
  } catch (const std::exception& e) {
    Refuse(lambda, e);
    return nullptr;
  }
  if (frequencies.size() != b->problem->frequencies.size())
    throw std::invalid_argument("the number of base frequencies changes with " + parameter_);
  b->problem->frequencies = std::move(frequencies);
  b->lambda = lambda;
  return b->residual.get();
}

CollocationResidual* ParameterizedResidual::Get(Built* b, double lambda) {
  if (b->lambda == lambda) return b->residual.get();
  if (only_frequencies_ && b->residual) return Retune(b, lambda);
  b->residual.reset();
  b->problem.reset();
  b->lambda = lambda;
  try {
    b->problem = std::make_unique<HarmonicBalanceProblem>(build_(lambda));
    b->residual = std::make_unique<CollocationResidual>(*b->problem, basis_, sampling_);
  } catch (const std::exception& e) {
    Refuse(lambda, e);
    b->residual.reset();
    return nullptr;
  }
  if (n_ >= 0 && (b->residual->num_unknowns() != n_ || b->residual->num_residuals() != m_))
    throw std::invalid_argument("the problem's structure changes with " + parameter_ + " (at " +
                                std::to_string(lambda) + ": " + std::to_string(b->residual->num_unknowns()) +
                                " unknowns, " + std::to_string(b->residual->num_residuals()) +
                                " residuals; at the start " + std::to_string(n_) + ", " + std::to_string(m_) + ")");
  return b->residual.get();
}

bool BorderedSystem::Evaluate(const Eigen::VectorXd& y, Eigen::VectorXd* residual, Eigen::MatrixXd* jacobian) {
  const int n = f_->n(), m = f_->m();
  if (!f_->Evaluate(y.head(n), y(n), &f_value_, jacobian ? &f_jacobian_ : nullptr)) return false;
  residual->resize(m + 1);
  residual->head(m) = f_value_;
  (*residual)(m) = direction_.dot(y - anchor_) - step_;
  if (jacobian) {
    jacobian->resize(m + 1, n + 1);
    jacobian->topRows(m) = f_jacobian_;
    jacobian->row(m) = direction_.transpose();
  }
  return true;
}

bool BranchTangent(ParameterizedResidual& f, const Eigen::VectorXd& y, const Eigen::VectorXd& previous,
                   Eigen::VectorXd* tangent) {
  const int n = f.n(), m = f.m();
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  if (!f.Evaluate(y.head(n), y(n), &F, &J)) return false;
  Eigen::MatrixXd A(m + 1, n + 1);
  A.topRows(m) = J;
  A.row(m) = previous.transpose();
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m + 1);
  rhs(m) = 1;
  // Square (the usual case): LU; overdetermined: least squares.
  const Eigen::VectorXd z = A.rows() == A.cols() ? Eigen::VectorXd(A.partialPivLu().solve(rhs))
                                                 : Eigen::VectorXd(A.colPivHouseholderQr().solve(rhs));
  const double norm = z.norm();
  if (!std::isfinite(norm) || norm == 0) return false;
  *tangent = z / norm;
  return true;
}

}  // namespace rmhb

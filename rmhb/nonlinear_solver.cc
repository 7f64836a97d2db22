#include "rmhb/nonlinear_solver.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "rmhb/dense_factorization.h"

namespace rmhb {
namespace {

double MaxAbs(const Eigen::VectorXd& v) { return v.size() ? v.cwiseAbs().maxCoeff() : 0.0; }

bool Finite(const Eigen::VectorXd& v) { return v.allFinite(); }

// Newton direction: exact solve when square, least squares otherwise. The
// factorisation is kept so that chord steps can reuse it: at a few hundred
// unknowns the O(n^3) factorisation dominates everything else.
class NewtonFactorization {
 public:
  void Factor(const Eigen::MatrixXd& J) {
    square_ = J.rows() == J.cols();
    if (square_) {
      lu_.compute(J);
      reciprocal_condition_ = lu_.rcond();
    } else {
      qr_.compute(J);
      const Eigen::VectorXd r = qr_.matrixQR().diagonal().cwiseAbs();
      reciprocal_condition_ = r.size() && r.maxCoeff() > 0 ? r.minCoeff() / r.maxCoeff() : 0;
    }
  }
  double reciprocal_condition() const { return reciprocal_condition_; }
  Eigen::VectorXd Step(const Eigen::VectorXd& F) const {
    return square_ ? Eigen::VectorXd(-lu_.solve(F)) : Eigen::VectorXd(-qr_.solve(F));
  }

 private:
  bool square_ = true;
  double reciprocal_condition_ = 0;
  DenseLu lu_;  // LAPACK: 1.4-2.4x faster than Eigen's at large n
  DenseQr qr_;
};

// (J'J + D) dx = -J'F through a Cholesky factorisation; D diagonal.
Eigen::VectorXd RegularizedStep(const Eigen::MatrixXd& JtJ, const Eigen::VectorXd& JtF,
                                const Eigen::VectorXd& diagonal) {
  Eigen::MatrixXd A = JtJ;
  A.diagonal() += diagonal;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
  return -ldlt.solve(JtF);
}

SolverSummary SolveWith(NonlinearProblem& problem, Eigen::VectorXd* x,
                        const SolverOptions& options);

}  // namespace

const char* ToString(SolverMethod m) {
  switch (m) {
    case SolverMethod::kAuto: return "auto";
    case SolverMethod::kNewton: return "newton";
    case SolverMethod::kLevenbergMarquardt: return "lm";
    case SolverMethod::kTikhonov: return "tikhonov";
  }
  return "?";
}

SolverMethod ParseSolverMethod(const std::string& name) {
  if (name == "auto") return SolverMethod::kAuto;
  if (name == "newton") return SolverMethod::kNewton;
  if (name == "lm") return SolverMethod::kLevenbergMarquardt;
  if (name == "tikhonov") return SolverMethod::kTikhonov;
  throw std::invalid_argument("unknown solver '" + name + "' (expected newton, lm, tikhonov or auto)");
}

const char* ToString(SolverStatus s) {
  switch (s) {
    case SolverStatus::kConverged: return "converged";
    case SolverStatus::kNoConvergence: return "not_converged";
    case SolverStatus::kFailure: return "failed";
    case SolverStatus::kInvalidInput: return "invalid_input";
  }
  return "?";
}

std::string SolverOptions::IsValid() const {
  if (max_iterations < 1) return "max_iterations must be >= 1";
  if (!(residual_tolerance >= 0) || !std::isfinite(residual_tolerance))
    return "residual_tolerance must be finite and >= 0";
  if (!(step_tolerance >= 0) || !std::isfinite(step_tolerance))
    return "step_tolerance must be finite and >= 0";
  if (!(acceptable_residual >= 0)) return "acceptable_residual must be >= 0";
  if (!(initial_lambda > 0) || !std::isfinite(initial_lambda)) return "initial_lambda must be > 0";
  if (!(lambda_factor > 1) || !std::isfinite(lambda_factor)) return "lambda_factor must be > 1";
  if (!(tikhonov_factor > 0) || !std::isfinite(tikhonov_factor)) return "tikhonov_factor must be > 0";
  if (!(max_seconds >= 0) || !std::isfinite(max_seconds))
    return "max_seconds must be finite and >= 0 (0: no limit)";
  if (fallback_max_iterations < 1) return "fallback_max_iterations must be >= 1";
  return "";
}

std::string SolverSummary::BriefReport() const {
  std::ostringstream out;
  out << "rmhb solver (" << ToString(method) << "): " << ToString(status) << ", " << iterations
      << " iterations, max|F| " << initial_residual << " -> " << final_residual << ", "
      << seconds * 1e3 << " ms";
  return out.str();
}

std::string SolverSummary::FullReport() const {
  std::ostringstream out;
  out << BriefReport() << "\n";
  out << "  unknowns " << num_unknowns << ", residuals " << num_residuals << ", evaluations "
      << evaluations << ", last step " << final_step << "\n";
  if (condition_estimate > 0) out << "  condition estimate of J: " << condition_estimate << "\n";
  if (reciprocal_condition > 0)
    out << "  reciprocal condition of the last factorised J: " << reciprocal_condition << "\n";
  if (!message.empty()) out << "  " << message << "\n";
  return out.str();
}

SolverSummary SolveNonlinear(NonlinearProblem& problem, Eigen::VectorXd* x,
                             const SolverOptions& options) {
  if (options.method != SolverMethod::kAuto) return SolveWith(problem, x, options);
  // Newton (Gauss-Newton when overdetermined) converges quadratically and is
  // the fastest from a good guess; Levenberg-Marquardt is the robust fallback
  // from the same start when it fails.
  const Eigen::VectorXd start = *x;
  SolverOptions o = options;
  o.method = SolverMethod::kNewton;
  SolverSummary newton = SolveWith(problem, x, o);
  if (newton.converged() || newton.status == SolverStatus::kInvalidInput) return newton;
  if (options.max_seconds > 0 && newton.seconds >= options.max_seconds) {
    std::ostringstream msg;
    msg << "Newton failed (" << newton.message << "); the time budget of " << options.max_seconds
        << " s is used up, no Levenberg-Marquardt fallback";
    newton.message = msg.str();
    return newton;
  }
  *x = start;
  o.method = SolverMethod::kLevenbergMarquardt;
  o.max_iterations = std::min(options.max_iterations, options.fallback_max_iterations);
  if (options.max_seconds > 0) o.max_seconds = options.max_seconds - newton.seconds;
  SolverSummary lm = SolveWith(problem, x, o);
  lm.iterations += newton.iterations;
  lm.evaluations += newton.evaluations;
  lm.seconds += newton.seconds;
  lm.message = "Newton failed (" + newton.message + "); Levenberg-Marquardt: " +
               (lm.message.empty() ? std::string("converged") : lm.message);
  return lm;
}

namespace {

SolverSummary SolveWith(NonlinearProblem& problem, Eigen::VectorXd* x,
                        const SolverOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SolverSummary s;
  s.num_unknowns = problem.num_unknowns();
  s.num_residuals = problem.num_residuals();
  auto finish = [&](SolverStatus status, std::string message) {
    s.status = status;
    s.message = std::move(message);
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return s;
  };
  if (std::string why = options.IsValid(); !why.empty())
    return finish(SolverStatus::kInvalidInput, "invalid options: " + why);
  if (x->size() != s.num_unknowns)
    return finish(SolverStatus::kInvalidInput, "initial guess has the wrong size");
  if (s.num_residuals < s.num_unknowns)
    return finish(SolverStatus::kInvalidInput,
                  "underdetermined: " + std::to_string(s.num_residuals) + " equations for " +
                      std::to_string(s.num_unknowns) + " unknowns");
  // A residual that cannot be evaluated is reported as infinite, never as the
  // default 0 (which would read as an exact solution).
  if (!Finite(*x)) {
    s.initial_residual = s.final_residual = INFINITY;
    return finish(SolverStatus::kInvalidInput, "initial guess is not finite");
  }

  const SolverMethod method = options.method;
  s.method = method;

  Eigen::VectorXd F(s.num_residuals), Ftrial(s.num_residuals), xtrial;
  Eigen::MatrixXd J(s.num_residuals, s.num_unknowns);
  ++s.evaluations;
  if (!problem.Evaluate(*x, &F, &J) || !Finite(F) || !J.allFinite()) {
    s.initial_residual = s.final_residual = INFINITY;
    return finish(SolverStatus::kFailure, "the initial guess gives non-finite residuals");
  }
  double norm = MaxAbs(F);
  s.initial_residual = s.final_residual = norm;
  s.residual_history.push_back(norm);
  double lambda = options.initial_lambda;
  int stalled = 0;
  NewtonFactorization factorization;
  bool factored = false, chord = false;

  auto out_of_time = [&] {
    return options.max_seconds > 0 &&
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
               options.max_seconds;
  };
  auto time_up = [&] {
    std::ostringstream msg;
    msg << "time budget of " << options.max_seconds << " s used up after " << s.iterations
        << " iterations (" << ToString(method) << "), max|F| = " << norm;
    return finish(SolverStatus::kNoConvergence, msg.str());
  };
  for (s.iterations = 1; s.iterations <= options.max_iterations; ++s.iterations) {
    if (norm <= options.residual_tolerance) {
      --s.iterations;
      break;
    }
    if (out_of_time()) {
      --s.iterations;
      return time_up();
    }
    Eigen::VectorXd dx;
    bool accepted = false;
    double damping = 1.0;
    double trial_norm = norm;
    if (method == SolverMethod::kNewton) {
      if (!factored) {
        factorization.Factor(J);
        s.reciprocal_condition = factorization.reciprocal_condition();
        factored = true;
        chord = false;
      }
      dx = factorization.Step(F);
      if (!Finite(dx)) return finish(SolverStatus::kFailure, "singular Jacobian (Newton step is not finite); try --solver lm");
      // Damping by Deuflhard's natural monotonicity test: accept x + t dx
      // when the simplified Newton correction |J^-1 F(x + t dx)| shrinks by
      // (1 - t/4). It is affine invariant, so the harmonic balance rows that
      // scale with k w do not dominate the test the way they dominate |F|^2,
      // and full steps are taken far earlier. The full step comes first.
      const double dx_norm = dx.norm();
      for (double t = 1.0; t > 1e-4; t *= 0.5) {
        xtrial = *x + t * dx;
        ++s.evaluations;
        if (problem.Evaluate(xtrial, &Ftrial, nullptr) && Finite(Ftrial)) {
          const double simplified = factorization.Step(Ftrial).norm();
          if (simplified <= (1 - 0.25 * t) * dx_norm) {
            accepted = true;
            dx *= t;
            damping = t;
            break;
          }
        }
        if (chord) break;  // a stale Jacobian: refresh rather than backtrack
      }
      if (!accepted && chord) {
        // Retry this iteration with a fresh Jacobian at the same point.
        ++s.evaluations;
        problem.Evaluate(*x, &F, &J);
        factored = false;
        --s.iterations;
        continue;
      }
      if (!accepted) {
        // Near the round-off floor no step decreases |F|: take the full step
        // once if it does not grow the residual much, else stop.
        xtrial = *x + dx;
        ++s.evaluations;
        if (problem.Evaluate(xtrial, &Ftrial, nullptr) && Finite(Ftrial) &&
            MaxAbs(Ftrial) <= 10 * norm + 1e-300)
          accepted = true;
      }
      if (accepted) {
        // Keep the factorisation while it still contracts fast (chord/
        // Shamanskii steps); otherwise refresh the Jacobian at the new point.
        const double ratio = MaxAbs(Ftrial) / std::max(norm, 1e-300);
        if (ratio < options.chord_contraction && MaxAbs(Ftrial) > options.residual_tolerance) {
          chord = true;
        } else {
          factored = false;
        }
      }
    } else {
      const Eigen::MatrixXd JtJ = J.transpose() * J;
      const Eigen::VectorXd JtF = J.transpose() * F;
      for (int attempt = 0; attempt < 30 && !accepted; ++attempt) {
        Eigen::VectorXd diagonal;
        if (method == SolverMethod::kLevenbergMarquardt) {
          diagonal = lambda * JtJ.diagonal().cwiseMax(1e-300);
        } else {
          diagonal = Eigen::VectorXd::Constant(s.num_unknowns,
                                               options.tikhonov_factor * std::sqrt(F.squaredNorm()) * lambda / options.initial_lambda);
        }
        dx = RegularizedStep(JtJ, JtF, diagonal);
        if (Finite(dx)) {
          xtrial = *x + dx;
          ++s.evaluations;
          if (problem.Evaluate(xtrial, &Ftrial, nullptr) && Finite(Ftrial) &&
              Ftrial.squaredNorm() < F.squaredNorm()) {
            accepted = true;
            lambda = std::max(lambda / options.lambda_factor, 1e-20);
            break;
          }
        }
        lambda *= options.lambda_factor;
        if (lambda > 1e20) break;
        if (out_of_time()) return time_up();
      }
      if (!accepted && MaxAbs(dx) <= options.step_tolerance * (1 + MaxAbs(*x)) * 1e3) {
        // Already at the floor: no step can reduce |F| in floating point.
        s.final_step = MaxAbs(dx);
        --s.iterations;
        if (norm > options.acceptable_residual)
          return finish(SolverStatus::kNoConvergence,
                        "stalled at max|F| = " + std::to_string(norm));
        return finish(SolverStatus::kConverged, "residual at its round-off floor");
      }
    }
    if (!accepted) {
      s.final_step = dx.size() ? MaxAbs(dx) : 0;
      return finish(SolverStatus::kNoConvergence,
                    "no step reduces the residual (max|F| = " + std::to_string(norm) +
                        "); the initial guess may be too far from a solution");
    }
    *x = xtrial;
    if (method == SolverMethod::kNewton && factored) {
      F = Ftrial;
    } else {
      ++s.evaluations;
      if (!problem.Evaluate(*x, &F, &J) || !Finite(F) || !J.allFinite())
        return finish(SolverStatus::kFailure, "non-finite residual or Jacobian during iteration");
    }
    trial_norm = MaxAbs(F);
    s.final_step = MaxAbs(dx);
    s.residual_history.push_back(trial_norm);
    if (options.verbose)
      std::fprintf(stderr, "  iter %3d  max|F| %.3e  step %.3e  damping %.3g%s\n", s.iterations,
                   trial_norm, s.final_step, damping, chord ? " (chord)" : "");
    stalled = trial_norm > 0.5 * norm ? stalled + 1 : 0;
    norm = trial_norm;
    s.final_residual = norm;
    if (norm <= options.residual_tolerance) break;
    if (s.final_step <= options.step_tolerance * (1 + MaxAbs(*x))) break;
    // Slow progress at a tiny step is a least-squares floor, not a failure.
    if (stalled >= 3 && s.final_step <= 1e3 * options.step_tolerance * (1 + MaxAbs(*x))) break;
  }
  if (s.reciprocal_condition == 0 && (method != SolverMethod::kNewton || s.iterations == 0)) {
    // Converged at the start (a warm start from a lower order), or a
    // regularised method that never factorised J itself: J is the final
    // Jacobian and the summary still owes its condition (one factorisation,
    // the cost of one more iteration). It is what says how near singular
    // the unregularised problem is (METHOD.md s.5).
    factorization.Factor(J);
    s.reciprocal_condition = factorization.reciprocal_condition();
  }
  if (options.estimate_condition) {
    if (method == SolverMethod::kNewton && factored) problem.Evaluate(*x, &F, &J);
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(J);
    const auto& sv = svd.singularValues();
    s.condition_estimate = sv(sv.size() - 1) > 0 ? sv(0) / sv(sv.size() - 1) : INFINITY;
  }
  if (norm > options.residual_tolerance && norm > options.acceptable_residual)
    return finish(SolverStatus::kNoConvergence,
                  "stalled at max|F| = " + std::to_string(norm) +
                      ": a stationary point of |F|^2 that is not a solution");
  if (s.iterations > options.max_iterations) {
    s.iterations = options.max_iterations;
    return finish(SolverStatus::kNoConvergence,
                  "iteration limit reached with max|F| = " + std::to_string(norm));
  }
  return finish(SolverStatus::kConverged, "");
}

}  // namespace
}  // namespace rmhb

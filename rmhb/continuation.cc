#include "rmhb/continuation.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace rmhb {

const char* ToString(ContinuationMethod method) {
  return method == ContinuationMethod::kNatural ? "natural" : "pseudo-arclength";
}

const char* ToString(ContinuationStatus status) {
  switch (status) {
    case ContinuationStatus::kCompleted: return "completed";
    case ContinuationStatus::kLeftRange: return "left_range";
    case ContinuationStatus::kStepTooSmall: return "step_too_small";
    case ContinuationStatus::kPointLimit: return "point_limit";
    case ContinuationStatus::kTimeLimit: return "time_limit";
    case ContinuationStatus::kStartFailed: return "start_failed";
  }
  return "unknown";
}

const char* ToString(PointStability stability) {
  switch (stability) {
    case PointStability::kStable: return "stable";
    case PointStability::kUnstable: return "unstable";
    case PointStability::kNeutral: return "neutral";
    case PointStability::kUnknown: break;
  }
  return "unknown";
}

std::string ContinuationOptions::IsValid() const {
  for (double s : {initial_step, max_step, min_step})
    if (!(s >= 0) || !std::isfinite(s)) return "steps must be finite and >= 0 (0: default)";
  if (max_step > 0 && initial_step > max_step) return "initial_step exceeds max_step";
  if (max_step > 0 && min_step > max_step) return "min_step exceeds max_step";
  if (min_step > 0 && initial_step > 0 && initial_step < min_step)
    return "initial_step is below min_step";
  if (!(step_growth >= 1) || !std::isfinite(step_growth)) return "step_growth must be >= 1";
  if (!(step_shrink > 0 && step_shrink < 1)) return "step_shrink must be in (0, 1)";
  if (fast_iterations < 0) return "fast_iterations must be >= 0";
  if (max_corrector_iterations < 1) return "max_corrector_iterations must be >= 1";
  if (!(max_turn > 0 && max_turn <= M_PI)) return "max_turn must be in (0, pi]";
  if (max_points < 2) return "max_points must be >= 2";
  if (max_stability_unknowns < 0) return "max_stability_unknowns must be >= 0";
  if (!(max_seconds >= 0)) return "max_seconds must be >= 0";
  if (!(fold_tolerance > 0)) return "fold_tolerance must be > 0";
  return harmonic_balance.IsValid();
}

std::string ContinuationSummary::BriefReport() const {
  std::ostringstream out;
  out << ToString(method) << " continuation in " << parameter << " from " << start << " to " << end
      << ": " << ToString(status);
  if (status != ContinuationStatus::kCompleted && !points.empty())
    out << " at " << parameter << " = " << points.back().parameter;
  out << ", " << points.size() << " points";
  if (method == ContinuationMethod::kPseudoArclength) out << ", " << num_folds << " fold(s)";
  out << ", " << accepted_steps << " steps (" << rejected_steps << " refused), arclength "
      << arclength << ", " << seconds * 1e3 << " ms";
  return out.str();
}

std::string ContinuationSummary::FullReport() const {
  std::ostringstream out;
  out << BriefReport() << "\n";
  if (!message.empty()) out << "  " << message << "\n";
  if (!stability_note.empty()) out << "  stability unknown: " << stability_note << "\n";
  out << "  order " << order << ", samples";
  for (int m : samples) out << " " << m;
  out << "\n";
  char line[200];
  for (const ContinuationPoint& p : points) {
    std::snprintf(line, sizeof line, "  %s = %-22.16g w = %-20.15g max|F| = %.1e  %-8s%s\n",
                  parameter.c_str(), p.parameter, p.solution.frequencies()[0], p.residual,
                  ToString(p.stability), p.fold ? "  fold" : "");
    out << line;
  }
  return out.str();
}

namespace {

using Clock = std::chrono::steady_clock;

// The harmonic balance residual F(x, lambda), rebuilding the problem when
// lambda changes. Two builds are kept: the current value and its
// finite-difference neighbour, so that a Newton iteration costs two builds.
class ParameterizedResidual {
 public:
  ParameterizedResidual(const ContinuationProblem& problem, HarmonicBasis basis, Sampling sampling)
      : problem_(problem), basis_(std::move(basis)), sampling_(std::move(sampling)) {
    CollocationResidual* r = At(problem.start);
    if (!r) throw std::invalid_argument("cannot build the problem at " + problem.parameter + " = " +
                                        std::to_string(problem.start) + ": " + refusal_);
    n_ = r->num_unknowns();
    m_ = r->num_residuals();
  }

  int n() const { return n_; }
  int m() const { return m_; }
  // Why the model last refused a value (empty when it has not since the
  // last ClearRefusal).
  const std::string& refusal() const { return refusal_; }
  void ClearRefusal() { refusal_.clear(); }
  const HarmonicBasis& basis() const { return basis_; }

  // The residual at lambda; nullptr when the model refuses the value.
  CollocationResidual* At(double lambda) { return Get(&current_, lambda); }
  // The problem at lambda (after At(lambda) has succeeded).
  const HarmonicBalanceProblem& ProblemAt(double lambda) {
    At(lambda);
    return *current_.problem;
  }

  // F(x, lambda) and, when `jacobian` is given, [F_x F_lambda] (m x (n+1)).
  bool Evaluate(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F,
                Eigen::MatrixXd* jacobian) {
    CollocationResidual* r = At(lambda);
    if (!r || !r->Evaluate(x, F, jacobian ? &jx_ : nullptr)) return false;
    if (!jacobian) return true;
    jacobian->resize(m_, n_ + 1);
    jacobian->leftCols(n_) = jx_;
    // Forward difference; backward where the model refuses lambda + h (the
    // edge of its domain, e.g. beta -> 1), which is then no refusal.
    const std::string refusal = refusal_;
    for (double h : {1e-7 * (1 + std::abs(lambda)), -1e-7 * (1 + std::abs(lambda))}) {
      CollocationResidual* shifted = Get(&neighbour_, lambda + h);
      if (shifted && shifted->Evaluate(x, &shifted_f_, nullptr)) {
        jacobian->col(n_) = (shifted_f_ - *F) / h;
        refusal_ = refusal;
        return jacobian->allFinite();
      }
    }
    return false;
  }

 private:
  struct Build {
    double lambda = std::numeric_limits<double>::quiet_NaN();
    // The residual refers to the problem: destroyed first, built second.
    std::unique_ptr<HarmonicBalanceProblem> problem;
    std::unique_ptr<CollocationResidual> residual;
  };

  CollocationResidual* Get(Build* b, double lambda) {
    if (b->lambda == lambda) return b->residual.get();
    b->residual.reset();
    b->problem.reset();
    b->lambda = lambda;
    try {
      b->problem = std::make_unique<HarmonicBalanceProblem>(problem_.build(lambda));
      b->residual = std::make_unique<CollocationResidual>(*b->problem, basis_, sampling_);
    } catch (const std::exception& e) {
      // A value outside the model's domain: this step fails, the trace goes on.
      std::ostringstream why;
      why << "at " << problem_.parameter << " = " << lambda << ": " << e.what();
      refusal_ = why.str();
      b->residual.reset();
      return nullptr;
    }
    if (n_ >= 0 && (b->residual->num_unknowns() != n_ || b->residual->num_residuals() != m_))
      throw std::invalid_argument(
          "the problem's structure changes with " + problem_.parameter + " (at " +
          std::to_string(lambda) + ": " + std::to_string(b->residual->num_unknowns()) +
          " unknowns, " + std::to_string(b->residual->num_residuals()) + " residuals; at the start " +
          std::to_string(n_) + ", " + std::to_string(m_) + ")");
    return b->residual.get();
  }

  const ContinuationProblem& problem_;
  HarmonicBasis basis_;
  Sampling sampling_;
  int n_ = -1, m_ = -1;
  std::string refusal_;
  Build current_, neighbour_;
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
  bool Evaluate(const Eigen::VectorXd& y, Eigen::VectorXd* residual,
                Eigen::MatrixXd* jacobian) override {
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

 private:
  ParameterizedResidual* f_;
  Eigen::VectorXd anchor_, direction_, f_value_;
  Eigen::MatrixXd f_jacobian_;
  double step_ = 0;
};

// The unit tangent of the branch at y, oriented along `previous`: the
// solution of [F_x F_lambda; previous'] t = e_last (least squares when the
// problem is overdetermined), normalised. false when it does not exist.
bool Tangent(ParameterizedResidual& f, const Eigen::VectorXd& y, const Eigen::VectorXd& previous,
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
  const Eigen::VectorXd z = A.colPivHouseholderQr().solve(rhs);
  const double norm = z.norm();
  if (!std::isfinite(norm) || norm == 0) return false;
  *tangent = z / norm;
  return true;
}

class Tracer {
 public:
  Tracer(const ContinuationProblem& problem, const ContinuationOptions& options,
         ParameterizedResidual* f, const std::vector<Variable>& variables, ContinuationSummary* summary)
      : problem_(problem), options_(options), f_(*f), system_(f), variables_(variables),
        summary_(*summary), start_(Clock::now()) {
    const double range = std::abs(problem.end - problem.start);
    direction_ = problem.end > problem.start ? 1 : -1;
    max_step_ = options.max_step > 0 ? options.max_step : range / 10;
    min_step_ = options.min_step > 0 ? options.min_step : std::min(1e-7 * range, max_step_);
    step_ = std::min(options.initial_step > 0 ? options.initial_step : range / 20, max_step_);
    corrector_ = options.harmonic_balance.solver;
    corrector_.method = SolverMethod::kNewton;
    corrector_.max_iterations = options.max_corrector_iterations;
    corrector_.max_seconds = 0;
    corrector_.estimate_condition = false;
  }

  void Natural(const Eigen::VectorXd& x0);
  void PseudoArclength(const Eigen::VectorXd& x0);

 private:
  int n() const { return f_.n(); }
  Eigen::VectorXd ParameterDirection() const {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(n() + 1);
    e(n()) = direction_;
    return e;
  }
  // Corrects *y from its predicted value; true when converged.
  bool Correct(const Eigen::VectorXd& anchor, const Eigen::VectorXd& direction, double step,
               Eigen::VectorXd* y, SolverSummary* report) {
    system_.Aim(anchor, direction, step);
    f_.ClearRefusal();
    *report = SolveNonlinear(system_, y, corrector_);
    summary_.corrector_iterations += report->iterations;
    return report->converged();
  }
  void Add(const Eigen::VectorXd& y, int iterations, double tangent_parameter, bool fold) {
    if (!summary_.points.empty()) {
      const ContinuationPoint& last = summary_.points.back();
      arclength_ += std::hypot((y.head(n()) - last_y_.head(n())).norm(), y(n()) - last.parameter);
    }
    last_y_ = y;
    CollocationResidual* r = f_.At(y(n()));
    // Evaluated there by the corrector, or at the range's end within an ulp.
    if (!r) throw std::runtime_error("the model refuses a converged point: " + f_.refusal());
    Eigen::MatrixXd coefficients;
    std::vector<double> w;
    r->Unpack(y.head(n()), &coefficients, &w);
    Eigen::VectorXd F;
    r->Evaluate(y.head(n()), &F, nullptr);
    summary_.points.push_back(ContinuationPoint{
        y(n()), HarmonicSolution(f_.basis(), w, coefficients, variables_), F.lpNorm<Eigen::Infinity>(),
        iterations, arclength_, tangent_parameter, fold, summary_.num_folds});
    summary_.arclength = arclength_;
    if (options_.stability) Classify(&summary_.points.back());
  }
  void Classify(ContinuationPoint* p) {
    if (hill_refused_) return;
    if (n() > options_.max_stability_unknowns) {
      hill_refused_ = true;
      summary_.stability_note = "not computed: " + std::to_string(n()) + " unknowns, over max_stability_unknowns = " +
                                std::to_string(options_.max_stability_unknowns);
      return;
    }
    try {
      const HillStabilityReport hill = HillStability(f_.ProblemAt(p->parameter), p->solution, options_.hill);
      const double margin = options_.hill.margin * p->solution.frequencies()[0];
      p->max_real_part = hill.max_real_part;
      p->stability = hill.stable                       ? PointStability::kStable
                     : hill.max_real_part > margin     ? PointStability::kUnstable
                                                       : PointStability::kNeutral;
    } catch (const std::invalid_argument& e) {
      // Outside the method's scope: the same for every point.
      hill_refused_ = true;
      summary_.stability_note = e.what();
    } catch (const std::runtime_error& e) {
      // QZ did not converge: likely so at the next points too, and costly.
      summary_.stability_note = e.what();
      hill_refused_ = ++hill_failures_ >= 2;
    }
  }
  // False (with the status set) when the point or time budget is spent.
  bool WithinBudget() {
    if (static_cast<int>(summary_.points.size()) >= options_.max_points) {
      summary_.status = ContinuationStatus::kPointLimit;
      summary_.message = "stopped after " + std::to_string(options_.max_points) + " points (max_points)";
      return false;
    }
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    if (options_.max_seconds > 0 && elapsed > options_.max_seconds) {
      summary_.status = ContinuationStatus::kTimeLimit;
      summary_.message = "stopped after " + std::to_string(elapsed) + " s (max_seconds)";
      return false;
    }
    return true;
  }
  // After a failed corrector: a smaller step, or false (status set) below
  // the minimum.
  bool Shrink(double near, const SolverSummary& report, const char* why) {
    ++summary_.rejected_steps;
    step_ *= options_.step_shrink;
    if (step_ >= min_step_) return true;
    std::ostringstream msg;
    msg << "the corrector failed near " << problem_.parameter << " = " << near << " down to the minimum step "
        << min_step_ << " (" << why << ", max|F| = " << report.final_residual << ")";
    if (!f_.refusal().empty())
      msg << "; the model refuses the parameter " << f_.refusal();
    else if (options_.method == ContinuationMethod::kNatural)
      msg << "; a turning point? pseudo-arclength continuation passes folds";
    summary_.status = ContinuationStatus::kStepTooSmall;
    summary_.message = msg.str();
    return false;
  }
  void Grow(int iterations) {
    if (iterations <= options_.fast_iterations) step_ = std::min(step_ * options_.step_growth, max_step_);
  }
  void LocateFold(const Eigen::VectorXd& y, const Eigen::VectorXd& t, double ds, double g_end);

  const ContinuationProblem& problem_;
  const ContinuationOptions& options_;
  ParameterizedResidual& f_;
  BorderedSystem system_;
  const std::vector<Variable>& variables_;
  ContinuationSummary& summary_;
  Clock::time_point start_;
  SolverOptions corrector_;
  double direction_ = 1, step_ = 0, max_step_ = 0, min_step_ = 0, arclength_ = 0;
  bool hill_refused_ = false;
  int hill_failures_ = 0;
  Eigen::VectorXd last_y_;
};

void Tracer::Natural(const Eigen::VectorXd& x0) {
  Eigen::VectorXd y(n() + 1), previous;
  y << x0, problem_.start;
  Add(y, 0, direction_, false);
  const Eigen::VectorXd e = ParameterDirection();
  while (direction_ * (problem_.end - y(n())) > 0) {
    if (!WithinBudget()) return;
    const double remaining = std::abs(problem_.end - y(n()));
    const double h = std::min(step_, remaining);
    // Secant predictor through the last two points.
    Eigen::VectorXd trial = y;
    if (previous.size()) trial += (y - previous) * (h / std::abs(y(n()) - previous(n())));
    trial(n()) = h == remaining ? problem_.end : y(n()) + direction_ * h;
    SolverSummary report;
    if (!Correct(y, e, h, &trial, &report)) {
      if (!Shrink(y(n()) + direction_ * h, report, "no convergence")) return;
      continue;
    }
    if (h == remaining) trial(n()) = problem_.end;  // exactly, not to round-off
    ++summary_.accepted_steps;
    previous = y;
    y = trial;
    Add(y, report.iterations, direction_, false);
    Grow(report.iterations);
  }
  summary_.status = ContinuationStatus::kCompleted;
}

void Tracer::LocateFold(const Eigen::VectorXd& y, const Eigen::VectorXd& t, double ds, double g_end) {
  // Regula falsi (Illinois) on g(s) = d lambda/ds at the corrected point s
  // along the arc from y: g(0) and g(ds) have opposite signs.
  double a = 0, ga = t(n()), b = ds, gb = g_end;
  Eigen::VectorXd best;
  double best_g = std::numeric_limits<double>::infinity();
  int best_iterations = 0, side = 0;
  for (int it = 0; it < 40; ++it) {
    const double s = (a * gb - b * ga) / (gb - ga);
    Eigen::VectorXd trial = y + s * t, tangent;
    SolverSummary report;
    if (!Correct(y, t, s, &trial, &report) || !Tangent(f_, trial, t, &tangent)) break;
    const double g = tangent(n());
    if (std::abs(g) < std::abs(best_g)) best = trial, best_g = g, best_iterations = report.iterations;
    if (std::abs(g) <= options_.fold_tolerance || b - a <= 1e-14 * ds) break;
    if (g * gb > 0) {
      b = s, gb = g;
      if (side == -1) ga /= 2;
      side = -1;
    } else {
      a = s, ga = g;
      if (side == 1) gb /= 2;
      side = 1;
    }
  }
  if (best.size()) Add(best, best_iterations, best_g, true);
}

void Tracer::PseudoArclength(const Eigen::VectorXd& x0) {
  Eigen::VectorXd y(n() + 1), t;
  y << x0, problem_.start;
  if (!Tangent(f_, y, ParameterDirection(), &t)) {
    Add(y, 0, 0, false);
    summary_.status = ContinuationStatus::kStepTooSmall;
    summary_.message = "no tangent at the start: the Jacobian [F_x F_lambda] is rank-deficient there";
    return;
  }
  Add(y, 0, t(n()), false);
  while (true) {
    if (!WithinBudget()) return;
    Eigen::VectorXd trial = y + step_ * t, tangent;
    SolverSummary report;
    const bool converged = Correct(y, t, step_, &trial, &report);
    if (!converged || !Tangent(f_, trial, t, &tangent) || tangent.dot(t) < std::cos(options_.max_turn)) {
      if (!Shrink(y(n()) + step_ * t(n()), report, converged ? "the tangent turned too far" : "no convergence"))
        return;
      continue;
    }
    ++summary_.accepted_steps;
    if (t(n()) * tangent(n()) < 0) {
      if (options_.locate_folds) LocateFold(y, t, step_, tangent(n()));
      ++summary_.num_folds;
    }
    const double lambda = trial(n());
    if (direction_ * (lambda - problem_.end) >= 0) {
      // Land exactly on the end, from the chord between the last two points.
      Eigen::VectorXd end = y + (trial - y) * ((problem_.end - y(n())) / (lambda - y(n())));
      end(n()) = problem_.end;
      Eigen::VectorXd anchor = Eigen::VectorXd::Zero(n() + 1);
      if (Correct(anchor, ParameterDirection(), direction_ * problem_.end, &end, &report)) {
        end(n()) = problem_.end;
        Eigen::VectorXd t_end;
        Add(end, report.iterations, Tangent(f_, end, tangent, &t_end) ? t_end(n()) : tangent(n()), false);
      } else {
        Add(trial, report.iterations, tangent(n()), false);
      }
      summary_.status = ContinuationStatus::kCompleted;
      return;
    }
    Add(trial, report.iterations, tangent(n()), false);
    if (direction_ * (lambda - problem_.start) < 0) {
      summary_.status = ContinuationStatus::kLeftRange;
      std::ostringstream msg;
      msg << "the branch turned back and left the range through " << problem_.parameter << " = "
          << problem_.start;
      summary_.message = msg.str();
      return;
    }
    y = trial;
    t = tangent;
    Grow(report.iterations);
  }
}

}  // namespace

ContinuationSummary TraceBranch(const ContinuationProblem& problem, const HarmonicSolution& guess,
                                const ContinuationOptions& options) {
  const auto start = Clock::now();
  if (std::string why = options.IsValid(); !why.empty())
    throw std::invalid_argument("invalid continuation options: " + why);
  if (!problem.build) throw std::invalid_argument("ContinuationProblem::build is empty");
  if (!std::isfinite(problem.start) || !std::isfinite(problem.end) || problem.start == problem.end)
    throw std::invalid_argument("the range of " + problem.parameter +
                                " must be two different finite values");
  ContinuationSummary summary;
  summary.method = options.method;
  summary.parameter = problem.parameter;
  summary.start = problem.start;
  summary.end = problem.end;

  // The first point: a full solve (order continuation, fallbacks) from the guess.
  const HarmonicBalanceProblem first = problem.build(problem.start);
  const int bases = static_cast<int>(first.frequencies.size());
  if (bases > 1 && options.harmonic_balance.quasi_periodic_sampling == QuasiPeriodicSampling::kGcd)
    throw std::invalid_argument(
        "continuation samples quasi-periodic solutions on the torus grid: the GCD rule's samples "
        "change with the frequency ratio");
  const HarmonicBalanceSummary solved = SolveHarmonicBalance(first, guess, options.harmonic_balance);
  summary.order = solved.order;
  summary.samples = solved.samples;
  auto finish = [&]() {
    summary.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return summary;
  };
  if (!solved.converged()) {
    std::ostringstream msg;
    msg << "no solution at " << problem.parameter << " = " << problem.start << ": "
        << solved.solver.message << " (max|F| = " << solved.solver.final_residual << ")";
    summary.message = msg.str();
    return finish();
  }
  ParameterizedResidual f(problem, MakeBasis(bases, options.harmonic_balance),
                          bases == 1 ? Sampling::Uniform(solved.samples[0]) : Sampling::Torus(solved.samples));
  const Eigen::VectorXd x0 =
      f.At(problem.start)->Pack(solved.solution->coefficients(), solved.solution->frequencies());
  Tracer tracer(problem, options, &f, first.system.variables(), &summary);
  if (options.method == ContinuationMethod::kNatural) tracer.Natural(x0);
  else tracer.PseudoArclength(x0);
  return finish();
}

}  // namespace rmhb

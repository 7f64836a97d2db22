#include "rmhb/continuation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "rmhb/branch_stability.h"
#include "rmhb/parameterized_residual.h"

namespace rmhb {

const char* ToString(ContinuationMethod method) {
  return method == ContinuationMethod::kNatural ? "natural" : "pseudo-arclength";
}

const char* ToString(StabilityMethod method) {
  switch (method) {
    case StabilityMethod::kAuto: return "auto";
    case StabilityMethod::kHill: return "hill";
    case StabilityMethod::kMonodromy: return "monodromy";
    case StabilityMethod::kHarmonicMonodromy: return "hb-monodromy";
    case StabilityMethod::kNone: break;
  }
  return "none";
}

StabilityMethod ParseStabilityMethod(const std::string& name) {
  for (StabilityMethod m : {StabilityMethod::kAuto, StabilityMethod::kHill, StabilityMethod::kMonodromy,
                            StabilityMethod::kHarmonicMonodromy})
    if (name == ToString(m)) return m;
  throw std::invalid_argument("unknown stability method '" + name + "' (auto, hill, monodromy, hb-monodromy)");
}

const char* ToString(ContinuationStatus status) {
  switch (status) {
    case ContinuationStatus::kCompleted: return "completed";
    case ContinuationStatus::kLeftRange: return "left_range";
    case ContinuationStatus::kStepTooSmall: return "step_too_small";
    case ContinuationStatus::kPointLimit: return "point_limit";
    case ContinuationStatus::kTimeLimit: return "time_limit";
    case ContinuationStatus::kStartFailed: return "start_failed";
    case ContinuationStatus::kStopped: return "stopped";
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
  if (max_hill_unknowns < 0 || max_cross_check_unknowns < 0) return "max_hill_unknowns and max_cross_check_unknowns must be >= 0";
  if (!(max_seconds >= 0)) return "max_seconds must be >= 0";
  if (!(fold_tolerance > 0)) return "fold_tolerance must be > 0";
  if (!(neutral_band >= 0 && neutral_band < 1)) return "neutral_band must be in [0, 1)";
  if (!(bifurcation_tolerance > 0) || !std::isfinite(bifurcation_tolerance))
    return "bifurcation_tolerance must be finite and > 0";
  if (stability_method == StabilityMethod::kNone) return "stability_method none: set stability = false instead";
  if (std::string why = harmonic_monodromy.IsValid(); !why.empty()) return "harmonic_monodromy: " + why;
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
  int counts[4] = {0, 0, 0, 0};
  for (const BifurcationPoint& b : bifurcations) ++counts[static_cast<int>(b.type)];
  for (BifurcationType type : {BifurcationType::kBranchPoint, BifurcationType::kPeriodDoubling,
                               BifurcationType::kNeimarkSacker})
    if (counts[static_cast<int>(type)] > 0) out << ", " << counts[static_cast<int>(type)] << " " << ShortName(type);
  out << ", " << accepted_steps << " steps (" << rejected_steps << " refused), arclength "
      << arclength << ", " << seconds * 1e3 << " ms";
  if (hill_points + monodromy_points + harmonic_monodromy_points > 0)
    out << " (stability: " << harmonic_monodromy_points << " hb-monodromy, " << hill_points << " Hill, "
        << monodromy_points << " monodromy, " << stability_seconds * 1e3 << " ms)";
  return out.str();
}

std::string ContinuationSummary::FullReport() const {
  std::ostringstream out;
  out << BriefReport() << "\n";
  if (!message.empty()) out << "  " << message << "\n";
  if (!stability_note.empty()) out << "  stability unknown at some points: " << stability_note << "\n";
  if (!stability_cross_check.empty()) out << "  stability cross-check: " << stability_cross_check << "\n";
  for (const BifurcationPoint& b : bifurcations) out << "  " << b.Describe(parameter) << "\n";
  out << "  order " << order << ", samples";
  for (int m : samples) out << " " << m;
  out << "\n";
  char line[240];
  for (const ContinuationPoint& p : points) {
    std::snprintf(line, sizeof line, "  %s = %-22.16g w = %-20.15g max|F| = %.1e  %-8s max|mu| = %-12.9g %-9s%s%s\n",
                  parameter.c_str(), p.parameter, p.solution.frequencies()[0], p.residual,
                  ToString(p.stability), p.max_multiplier, ToString(p.stability_method),
                  p.bifurcation >= 0 ? "  " : "",
                  p.bifurcation >= 0 ? ShortName(bifurcations[p.bifurcation].type) : "");
    out << line;
  }
  return out.str();
}

namespace {

using Clock = std::chrono::steady_clock;

// A point found inside a step (a fold or a bifurcation), added before the
// step's end point in the order of its arclength s from the step's start.
struct Event {
  double s = 0;
  ContinuationPoint point;
  BifurcationPoint bifurcation;
  bool at_step_end = false;  // not located: it marks the step's own end point
};

class Tracer {
 public:
  Tracer(const ContinuationProblem& problem, const ContinuationOptions& options,
         ParameterizedResidual* f, const std::vector<Variable>& variables, ContinuationSummary* summary)
      : problem_(problem), options_(options), f_(*f), system_(f), variables_(variables),
        summary_(*summary), stability_(problem, options, f->n()), start_(Clock::now()) {
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
    // Nothing on a branch reads a corrector's condition estimate; it was 8 %
    // of the Duffing response's time per point at N = 15 (issue 14).
    corrector_.report_condition = false;
  }
  // Into the summary: how stability was computed, and why not where not.
  void Close() {
    summary_.hill_points = stability_.hill_points();
    summary_.monodromy_points = stability_.monodromy_points();
    summary_.harmonic_monodromy_points = stability_.harmonic_points();
    summary_.stability_seconds = stability_.seconds();
    summary_.stability_cross_check = stability_.cross_check();
    if (unknown_points_ > 0) summary_.stability_note = stability_.note();
  }

  void Natural(const Eigen::VectorXd& x0);
  void PseudoArclength(const Eigen::VectorXd& x0);
  // From a solution y0 = (x0, lambda0) along the direction t0 (branch switching).
  void PseudoArclengthFrom(const Eigen::VectorXd& y0, const Eigen::VectorXd& t0);

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
  // The point y = (x, lambda) as a solution, with its stability.
  ContinuationPoint MakePoint(const Eigen::VectorXd& y, int iterations, double tangent_parameter, bool fold) {
    CollocationResidual* r = f_.At(y(n()));
    // Evaluated there by the corrector, or at the range's end within an ulp.
    if (!r) throw std::runtime_error("the model refuses a converged point: " + f_.refusal());
    Eigen::MatrixXd coefficients;
    std::vector<double> w;
    r->Unpack(y.head(n()), &coefficients, &w);
    Eigen::VectorXd F;
    r->Evaluate(y.head(n()), &F, nullptr);
    ContinuationPoint p(y(n()), HarmonicSolution(f_.basis(), w, coefficients, variables_));
    p.residual = F.lpNorm<Eigen::Infinity>();
    p.iterations = iterations;
    p.tangent_parameter = tangent_parameter;
    p.fold = fold;
    if (options_.stability && !stability_.Classify(f_.ProblemAt(p.parameter), &p)) ++unknown_points_;
    return p;
  }
  void Add(ContinuationPoint p, const Eigen::VectorXd& y) {
    if (!summary_.points.empty())
      arclength_ += std::hypot((y.head(n()) - last_y_.head(n())).norm(), y(n()) - summary_.points.back().parameter);
    last_y_ = y;
    p.arclength = arclength_;
    p.folds_before = summary_.num_folds;
    for (BifurcationPoint& b : pending_) {  // crossings that could not be located, marked here
      b.point = static_cast<int>(summary_.points.size());
      b.parameter = p.parameter;
      p.bifurcation = static_cast<int>(summary_.bifurcations.size());
      summary_.bifurcations.push_back(b);
    }
    pending_.clear();
    summary_.points.push_back(std::move(p));
    summary_.arclength = arclength_;
  }
  // The events of the step from y (point `before`) to the point `after`,
  // located and added in arclength order; those beyond the range's end are
  // dropped. `chord`: the predictor's direction, `condition` . (y' - y) = s
  // the corrector's; `fold`: the tangent's parameter component changed sign.
  void AddEvents(const ContinuationPoint& before, const ContinuationPoint& after, const Eigen::VectorXd& y,
                 const Eigen::VectorXd& chord, const Eigen::VectorXd& condition, double ds, bool fold,
                 double tangent_after);
  // A sign change of a test function is noise, not a crossing, when at both
  // points every non-trivial multiplier, real or complex, that is near where
  // it crosses (+1, -1, the unit circle) lies within the neutral band of it.
  // Of either kind: a conservative orbit's second +1 is by round-off a real
  // pair 1 +- e at one point and a complex pair 1 +- i e at the next, which
  // flips the branch-point and the torus test functions alike (the
  // relativistic sweep at N = 80 reported three branch points and two
  // "located" Neimark-Sacker points, and took 64 s instead of 10).
  bool Decidable(BifurcationType type, const ContinuationPoint& before, const ContinuationPoint& after) const {
    return std::max(Nearness(before, type), Nearness(after, type)) > 10 * options_.neutral_band;
  }
  static double Nearness(const ContinuationPoint& p, BifurcationType type) {
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < p.multipliers.size(); ++i) {
      if (static_cast<int>(i) == p.trivial_multiplier) continue;
      const std::complex<double> mu = p.multipliers[i];
      const double d = type == BifurcationType::kNeimarkSacker   ? std::abs(std::abs(mu) - 1)
                       : type == BifurcationType::kPeriodDoubling ? std::abs(mu + 1.0)
                                                                  : std::abs(mu - 1.0);
      nearest = std::min(nearest, d);
    }
    return nearest;
  }
  std::optional<Event> LocateFold(const Eigen::VectorXd& y, const Eigen::VectorXd& t, double ds, double g_end);
  std::optional<Event> LocateCrossing(BifurcationType type, const ContinuationPoint& before,
                                      const ContinuationPoint& after, const Eigen::VectorXd& y,
                                      const Eigen::VectorXd& chord, const Eigen::VectorXd& condition, double ds);
  // False (with the status set) when stop_when says so.
  bool GoOn() {
    if (!problem_.stop_when) return true;
    const std::string why = problem_.stop_when(summary_.points.back());
    if (why.empty()) return true;
    summary_.status = ContinuationStatus::kStopped;
    summary_.message = why;
    return false;
  }
  // The pseudo-arclength steps from the solution y with unit tangent t.
  void ArclengthSteps(Eigen::VectorXd y, Eigen::VectorXd t);
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

  const ContinuationProblem& problem_;
  const ContinuationOptions& options_;
  ParameterizedResidual& f_;
  BorderedSystem system_;
  const std::vector<Variable>& variables_;
  ContinuationSummary& summary_;
  BranchStability stability_;
  Clock::time_point start_;
  SolverOptions corrector_;
  double direction_ = 1, step_ = 0, max_step_ = 0, min_step_ = 0, arclength_ = 0;
  int unknown_points_ = 0;
  // The first point of a switched branch sits on the bifurcation: no
  // crossing is counted from it.
  bool skip_detection_ = false;
  std::vector<BifurcationPoint> pending_;
  Eigen::VectorXd last_y_;
};

void Tracer::Natural(const Eigen::VectorXd& x0) {
  Eigen::VectorXd y(n() + 1), previous;
  y << x0, problem_.start;
  Add(MakePoint(y, 0, direction_, false), y);
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
    ContinuationPoint next = MakePoint(trial, report.iterations, direction_, false);
    AddEvents(summary_.points.back(), next, y, (trial - y) / h, e, h, false, direction_);
    Add(std::move(next), trial);
    if (!GoOn()) return;
    previous = y;
    y = trial;
    Grow(report.iterations);
  }
  summary_.status = ContinuationStatus::kCompleted;
}

std::optional<Event> Tracer::LocateFold(const Eigen::VectorXd& y, const Eigen::VectorXd& t, double ds,
                                        double g_end) {
  // Regula falsi (Illinois) on g(s) = d lambda/ds at the corrected point s
  // along the arc from y: g(0) and g(ds) have opposite signs.
  double a = 0, ga = t(n()), b = ds, gb = g_end;
  Eigen::VectorXd best;
  double best_g = std::numeric_limits<double>::infinity(), best_s = 0;
  int best_iterations = 0, side = 0, iterations = 0;
  for (; iterations < 40; ++iterations) {
    const double s = (a * gb - b * ga) / (gb - ga);
    Eigen::VectorXd trial = y + s * t, tangent;
    SolverSummary report;
    if (!Correct(y, t, s, &trial, &report) || !BranchTangent(f_, trial, t, &tangent)) break;
    const double g = tangent(n());
    if (std::abs(g) < std::abs(best_g)) best = trial, best_g = g, best_iterations = report.iterations, best_s = s;
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
  if (!best.size()) return std::nullopt;
  Event event{best_s, MakePoint(best, best_iterations, best_g, true), {}};
  BifurcationPoint& fold = event.bifurcation;
  fold.type = BifurcationType::kFold;
  fold.parameter = best(n());
  fold.distance = best_g;
  fold.tolerance = options_.fold_tolerance;
  fold.located = std::abs(best_g) <= options_.fold_tolerance;
  fold.iterations = iterations;
  fold.method = "tangent";
  double distance = 0;
  CriticalMultiplier(event.point.multipliers, event.point.trivial_multiplier, BifurcationType::kFold,
                     &fold.multiplier, &distance);
  return event;
}

std::optional<Event> Tracer::LocateCrossing(BifurcationType type, const ContinuationPoint& before,
                                            const ContinuationPoint& after, const Eigen::VectorXd& y,
                                            const Eigen::VectorXd& chord, const Eigen::VectorXd& condition,
                                            double ds) {
  auto sign = [type](const ContinuationPoint& p) {
    const TestFunctionSigns s = TestSigns(p.multipliers, p.trivial_multiplier);
    return type == BifurcationType::kPeriodDoubling ? s.minus : type == BifurcationType::kNeimarkSacker ? s.torus : s.plus;
  };
  auto distance = [type](const ContinuationPoint& p, double* g, std::complex<double>* mu) {
    return CriticalMultiplier(p.multipliers, p.trivial_multiplier, type, mu, g);
  };
  // Bracket [a, b] in s kept by the test function's sign; inside it the
  // secant of the critical multiplier's distance g when g changes sign
  // across the bracket (Illinois), else bisection.
  const int sign_a = sign(before);
  double a = 0, b = ds, ga = 0, gb = 0, lambda_a = before.parameter, lambda_b = after.parameter;
  std::complex<double> mu;
  bool valid_a = distance(before, &ga, &mu), valid_b = distance(after, &gb, &mu);
  double raw_a = ga, raw_b = gb;  // g at the bracket's ends, without Illinois' halving
  std::optional<Event> best;
  double best_g = std::numeric_limits<double>::infinity();
  int side = 0, iterations = 0;
  for (; iterations < 40; ++iterations) {
    double s = 0.5 * (a + b);
    if (valid_a && valid_b && ga * gb < 0) s = (a * gb - b * ga) / (gb - ga);
    if (!(s > a && s < b)) s = 0.5 * (a + b);
    Eigen::VectorXd trial = y + s * chord, tangent;
    SolverSummary report;
    if (!Correct(y, condition, s, &trial, &report)) break;
    const double tangent_parameter = BranchTangent(f_, trial, chord, &tangent) ? tangent(n()) : chord(n());
    ContinuationPoint p = MakePoint(trial, report.iterations, tangent_parameter, false);
    if (p.stability_method == StabilityMethod::kNone) break;
    double g = 0;
    const bool valid = distance(p, &g, &mu);
    const int sign_p = sign(p);
    if (valid && std::abs(g) < std::abs(best_g)) {
      best_g = g;
      best = Event{s, p, {}};
      best->bifurcation.multiplier = mu;
    }
    if (valid && std::abs(g) <= options_.bifurcation_tolerance) break;
    if (sign_p == sign_a) {
      a = s, ga = raw_a = g, valid_a = valid, lambda_a = p.parameter;
      if (side == 1) gb /= 2;
      side = 1;
    } else {
      b = s, gb = raw_b = g, valid_b = valid, lambda_b = p.parameter;
      if (side == -1) ga /= 2;
      side = -1;
    }
    if (b - a <= 1e-13 * ds) break;
  }
  // A psi_NS sign change without a complex pair on the circle is a neutral
  // saddle (two real multipliers with product 1): no bifurcation. Unless a
  // pair did cross between the step's ends and the location missed the
  // circle: the multipliers of a non-smooth orbit jump at grazing (NLvib's
  // example 03 at W = 0.5819: |mu| 1.16 to 0.94 within 4e-6), and that
  // crossing is reported, not located.
  if (best && type == BifurcationType::kNeimarkSacker && std::abs(best_g) > 1e-3 &&
      TestSigns(before.multipliers, before.trivial_multiplier).pairs ==
          TestSigns(after.multipliers, after.trivial_multiplier).pairs)
    return std::nullopt;
  if (!best) {
    // The location failed from its first trial (the corrector, or no
    // multipliers there): the crossing is reported at the step's end point,
    // not located, with the whole step as its bracket.
    best = Event{ds, after, {}};
    best->at_step_end = true;
    if (!distance(after, &best_g, &best->bifurcation.multiplier)) best_g = NAN;
  }
  BifurcationPoint& bif = best->bifurcation;
  bif.type = type;
  bif.parameter = best->point.parameter;
  bif.distance = best_g;
  bif.tolerance = options_.bifurcation_tolerance;
  bif.located = std::abs(best_g) <= options_.bifurcation_tolerance;
  bif.parameter_bracket = std::abs(lambda_b - lambda_a);
  // |g| over the secant slope dg/dlambda across the last bracket.
  if (valid_a && valid_b && raw_a != raw_b && lambda_a != lambda_b)
    bif.parameter_error = std::abs(best_g * (lambda_b - lambda_a) / (raw_b - raw_a));
  bif.iterations = iterations;
  bif.method = ToString(best->point.stability_method);
  if (type == BifurcationType::kNeimarkSacker)
    bif.torus_frequency = best->point.solution.frequencies()[0] * std::arg(bif.multiplier) / (2 * M_PI);
  return best;
}

void Tracer::AddEvents(const ContinuationPoint& before_ref, const ContinuationPoint& after, const Eigen::VectorXd& y,
                       const Eigen::VectorXd& chord, const Eigen::VectorXd& condition, double ds, bool fold,
                       double tangent_after) {
  const ContinuationPoint before = before_ref;  // summary_.points grows below
  std::vector<Event> events;
  if (fold && options_.locate_folds)
    if (auto e = LocateFold(y, chord, ds, tangent_after)) events.push_back(std::move(*e));
  const bool compare = options_.detect_bifurcations && !skip_detection_ &&
                       before.stability_method != StabilityMethod::kNone &&
                       after.stability_method != StabilityMethod::kNone &&
                       (before.trivial_multiplier < 0) == (after.trivial_multiplier < 0);
  skip_detection_ = false;
  if (compare) {
    const TestFunctionSigns s0 = TestSigns(before.multipliers, before.trivial_multiplier);
    const TestFunctionSigns s1 = TestSigns(after.multipliers, after.trivial_multiplier);
    std::vector<BifurcationType> crossed;
    // A fold moves a real multiplier through +1 too: not a branch point.
    if (s0.plus != s1.plus && !fold) crossed.push_back(BifurcationType::kBranchPoint);
    if (s0.minus != s1.minus) crossed.push_back(BifurcationType::kPeriodDoubling);
    if (s0.torus != s1.torus) crossed.push_back(BifurcationType::kNeimarkSacker);
    for (BifurcationType type : crossed)
      if (Decidable(type, before, after))
        if (auto e = LocateCrossing(type, before, after, y, chord, condition, ds)) events.push_back(std::move(*e));
  }
  std::sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.s < b.s; });
  for (Event& e : events) {
    if (e.at_step_end) {
      pending_.push_back(e.bifurcation);
      continue;
    }
    if (direction_ * (e.point.parameter - problem_.end) > 0) continue;  // beyond the range
    const Eigen::VectorXd ye = f_.At(e.point.parameter)->Pack(e.point.solution.coefficients(),
                                                              e.point.solution.frequencies());
    Eigen::VectorXd y_event(n() + 1);
    y_event << ye, e.point.parameter;
    e.point.bifurcation = static_cast<int>(summary_.bifurcations.size());
    e.bifurcation.point = static_cast<int>(summary_.points.size());
    summary_.bifurcations.push_back(e.bifurcation);
    Add(std::move(e.point), y_event);
  }
}

void Tracer::PseudoArclength(const Eigen::VectorXd& x0) {
  Eigen::VectorXd y(n() + 1), t;
  y << x0, problem_.start;
  if (!BranchTangent(f_, y, ParameterDirection(), &t)) {
    Add(MakePoint(y, 0, 0, false), y);
    summary_.status = ContinuationStatus::kStepTooSmall;
    summary_.message = "no tangent at the start: the Jacobian [F_x F_lambda] is rank-deficient there";
    return;
  }
  Add(MakePoint(y, 0, t(n()), false), y);
  ArclengthSteps(y, t);
}

void Tracer::PseudoArclengthFrom(const Eigen::VectorXd& y0, const Eigen::VectorXd& t0) {
  Add(MakePoint(y0, 0, t0(n()), false), y0);
  skip_detection_ = true;
  ArclengthSteps(y0, t0.normalized());
}

void Tracer::ArclengthSteps(Eigen::VectorXd y, Eigen::VectorXd t) {
  while (true) {
    if (!WithinBudget()) return;
    Eigen::VectorXd trial = y + step_ * t, tangent;
    SolverSummary report;
    const bool converged = Correct(y, t, step_, &trial, &report);
    if (!converged || !BranchTangent(f_, trial, t, &tangent) || tangent.dot(t) < std::cos(options_.max_turn)) {
      if (!Shrink(y(n()) + step_ * t(n()), report, converged ? "the tangent turned too far" : "no convergence"))
        return;
      continue;
    }
    ++summary_.accepted_steps;
    const bool fold = t(n()) * tangent(n()) < 0;
    ContinuationPoint next = MakePoint(trial, report.iterations, tangent(n()), false);
    AddEvents(summary_.points.back(), next, y, t, t, step_, fold, tangent(n()));
    if (fold) ++summary_.num_folds;
    const double lambda = trial(n());
    if (direction_ * (lambda - problem_.end) >= 0) {
      // Land exactly on the end, from the chord between the last two points.
      Eigen::VectorXd end = y + (trial - y) * ((problem_.end - y(n())) / (lambda - y(n())));
      end(n()) = problem_.end;
      Eigen::VectorXd anchor = Eigen::VectorXd::Zero(n() + 1);
      if (Correct(anchor, ParameterDirection(), direction_ * problem_.end, &end, &report)) {
        end(n()) = problem_.end;
        Eigen::VectorXd t_end;
        const double g = BranchTangent(f_, end, tangent, &t_end) ? t_end(n()) : tangent(n());
        Add(MakePoint(end, report.iterations, g, false), end);
      } else {
        Add(std::move(next), trial);
      }
      summary_.status = ContinuationStatus::kCompleted;
      return;
    }
    Add(std::move(next), trial);
    if (!GoOn()) return;
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

void CheckArguments(const ContinuationProblem& problem, const ContinuationOptions& options) {
  if (std::string why = options.IsValid(); !why.empty())
    throw std::invalid_argument("invalid continuation options: " + why);
  if (!problem.build) throw std::invalid_argument("ContinuationProblem::build is empty");
  if (!std::isfinite(problem.start) || !std::isfinite(problem.end) || problem.start == problem.end)
    throw std::invalid_argument("the range of " + problem.parameter +
                                " must be two different finite values");
  if (problem.period_multiple < 1) throw std::invalid_argument("ContinuationProblem::period_multiple must be >= 1");
}

// Those of `found` that the equations keep halfway and at the end of the
// range too: a parameter may multiply a term that breaks one (a x^2 from
// a = 0), and a branch held to it there would have no tangent or a wrong
// solution.
std::vector<HalfTurnSymmetry> KeptAlong(const ContinuationProblem& problem, std::vector<HalfTurnSymmetry> found) {
  for (double value : {0.5 * (problem.start + problem.end), problem.end}) {
    if (found.empty()) break;
    const std::vector<HalfTurnSymmetry> there = ImposableSymmetries(problem.build(value));
    auto lost = [&](const HalfTurnSymmetry& s) {
      return std::none_of(there.begin(), there.end(), [&](const HalfTurnSymmetry& t) { return t.Mask() == s.Mask(); });
    };
    found.erase(std::remove_if(found.begin(), found.end(), lost), found.end());
  }
  return found;
}

}  // namespace

ContinuationSummary TraceBranch(const ContinuationProblem& problem, const HarmonicSolution& guess,
                                const ContinuationOptions& options) {
  const auto start = Clock::now();
  CheckArguments(problem, options);
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
  // The solved basis (order selection or the adaptive index set may have
  // moved it from the options', METHOD.md s.8), and the symmetries order
  // selection or the adaptive set found and imposed, where the equations
  // keep them along the range: the branch stays in that symmetric subspace
  // (Newton's iterates from a symmetric point do), at a quarter of the
  // unknowns per pair of reflections.
  const std::vector<HalfTurnSymmetry> found = KeptAlong(problem, solved.symmetries_found);
  const ParameterizedResidual::Build build = [&problem, found](double value) {
    HarmonicBalanceProblem p = problem.build(value);
    p.symmetries.insert(p.symmetries.end(), found.begin(), found.end());
    return p;
  };
  ParameterizedResidual f(problem.parameter, found.empty() ? problem.build : build, problem.start,
                          solved.solution->basis(),
                          bases == 1 ? Sampling::Uniform(solved.samples[0]) : Sampling::Torus(solved.samples),
                          problem.only_frequencies_change);
  const Eigen::VectorXd x0 =
      f.At(problem.start)->Pack(solved.solution->coefficients(), solved.solution->frequencies());
  Tracer tracer(problem, options, &f, first.system.variables(), &summary);
  if (options.method == ContinuationMethod::kNatural) tracer.Natural(x0);
  else tracer.PseudoArclength(x0);
  tracer.Close();
  return finish();
}

ContinuationSummary TraceBranchFrom(const ContinuationProblem& problem, double parameter,
                                    const HarmonicSolution& start, const HarmonicSolution& direction,
                                    const ContinuationOptions& options) {
  const auto clock_start = Clock::now();
  CheckArguments(problem, options);
  if (direction.basis().harmonics() != start.basis().harmonics() ||
      direction.coefficients().rows() != start.coefficients().rows())
    throw std::invalid_argument("TraceBranchFrom: the direction must be on the start's basis and variables");
  ContinuationSummary summary;
  summary.method = ContinuationMethod::kPseudoArclength;
  summary.parameter = problem.parameter;
  summary.start = problem.start;
  summary.end = problem.end;
  const HarmonicBalanceProblem first = problem.build(parameter);
  const HarmonicBasis& basis = start.basis();
  std::vector<int> samples = options.harmonic_balance.samples;
  if (samples.empty()) samples = SamplesForRule(first.system, basis, options.harmonic_balance.rule);
  summary.order = basis.order();
  summary.samples = samples;
  ParameterizedResidual f(problem.parameter, problem.build, parameter, basis,
                          basis.num_bases() == 1 ? Sampling::Uniform(samples[0]) : Sampling::Torus(samples),
                          problem.only_frequencies_change);
  CollocationResidual* r = f.At(parameter);
  Eigen::VectorXd y0(f.n() + 1), t0(f.n() + 1);
  y0 << r->Pack(start.coefficients(), start.frequencies()), parameter;
  std::vector<double> no_shift(start.frequencies().size(), 0.0);
  t0 << r->Pack(direction.coefficients(), no_shift), 0;
  if (!(t0.norm() > 0)) throw std::invalid_argument("TraceBranchFrom: the direction is zero");
  Tracer tracer(problem, options, &f, first.system.variables(), &summary);
  tracer.PseudoArclengthFrom(y0, t0);
  tracer.Close();
  summary.seconds = std::chrono::duration<double>(Clock::now() - clock_start).count();
  return summary;
}

}  // namespace rmhb

#include "rmhb/pipeline/branch.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>

#include "rmhb/pipeline/monodromy.h"
#include "rmhb/pipeline/report.h"
#include "rmhb/pipeline/stability.h"
#include "rmhb/pipeline/start.h"
#include "rmhb/pipeline/torus.h"
#include "rmhb/truncation_estimate.h"

namespace rmhb {
namespace {

using nlohmann::json;

// `period_multiple` 2 on a period-doubled branch: its solution has base w/2
// while the model's equations keep the forcing w; the reference and the
// definitions are the period-T model's and are not checked there. The
// definitions come from the trace's problem (`problem`, the period-T one),
// which needs no rebuild of the model; the whole model at the point is
// rebuilt only for what needs it (a reference, validation, a torus).
BranchPointReport ReportPoint(const Model& model, const ContinueOptions& o, const ContinuationProblem& problem,
                              const ContinuationSummary& branch, const ContinuationPoint& p, int period_multiple = 1) {
  BranchPointReport r;
  r.peak = PeakValue(p.solution);
  r.stability = ToString(p.stability);
  std::optional<Model> rebuilt;
  auto here_model = [&]() -> const Model& {
    if (!rebuilt) rebuilt = WithParameters(model, {{o.parameter, p.parameter}});
    return *rebuilt;
  };
  if (period_multiple == 1) {
    const HarmonicBalanceProblem here = problem.build(p.parameter);
    if (here.definitions) r.definitions = CheckDefinitions(p.solution, here.definitions, branch.samples);
    if (model.reference.has_frequency() || model.reference.has_amplitude()) {
      const ReferenceErrors errors = ErrorsAgainst(here_model().reference, p.solution);
      r.frequency_error = errors.frequency;
      r.amplitude_error = errors.amplitude;
    }
  }
  if (o.validate) {
    const auto& w = p.solution.frequencies();
    const double t_end = o.validate_periods * 2 * M_PI / *std::min_element(w.begin(), w.end());
    integrators::ValidationReport v;
    const Model& here = here_model();
    if (period_multiple == 1) {
      v = ValidateOriginal(here, p.solution, t_end, 401);
    } else {
      std::vector<double> bases = w;
      for (double& b : bases) b *= period_multiple;
      auto claimed = [&](double t) { return here.state(p.solution, t); };
      v = here.original_dae ? integrators::ValidateDaeTrajectory(here.original_dae(bases), claimed, t_end, 401)
                            : integrators::ValidateTrajectory(here.original(bases), claimed, t_end, here.stiff, 401);
    }
    r.validation_error = v.ok ? v.max_error : NAN;
  }
  if (p.solution.frequencies().size() > 1) {
    r.outermost = OutermostCoefficients(p.solution);
    r.ratio = p.solution.frequencies()[1] / p.solution.frequencies()[0];
    if (o.stability) {
      r.lyapunov = TorusStability(here_model(), p.solution, o.torus_stability);
      r.stability = ToString(r.lyapunov->stability);
    }
  }
  return r;
}

ContinuationOptions TraceOptions(const ContinueOptions& o) {
  ContinuationOptions options;
  options.method = o.natural ? ContinuationMethod::kNatural : ContinuationMethod::kPseudoArclength;
  options.harmonic_balance = o.harmonic_balance;
  options.stability = o.stability;
  options.stability_method = o.stability_method;
  const double range = std::abs(o.to - o.from);
  options.initial_step = range / o.steps;
  options.max_step = o.max_step > 0 ? o.max_step : std::max(options.initial_step, range / 10);
  options.initial_step = std::min(options.initial_step, options.max_step);
  return options;
}

// The parameter of a period doubling where an earlier doubled branch
// merged back, or NaN: that branch is the one it would start.
double TracedFrom(const std::vector<DoubledBranchReport>& doubled, const BifurcationPoint& pd) {
  for (const DoubledBranchReport& d : doubled)
    if (d.branch.branch && d.branch.branch->status == ContinuationStatus::kStopped)
      for (const ContinuationPoint& p : d.branch.branch->points)
        if (std::abs(p.parameter - pd.parameter) <= 1e-6 * (1 + std::abs(pd.parameter))) return d.from.parameter;
  return std::numeric_limits<double>::quiet_NaN();
}

void SwitchBranches(const Model& model, const ContinueOptions& o, const ContinuationProblem& problem,
                    const ContinuationOptions& options, BranchSummary* b) {
  const ContinuationSummary& s = b->continuation;
  for (const BifurcationPoint& bif : s.bifurcations) {
    if (bif.type == BifurcationType::kPeriodDoubling) {
      DoubledBranchReport d{bif, {}, {}};
      if (const double from = TracedFrom(b->doubled, bif); std::isfinite(from)) {
        char text[200];
        std::snprintf(text, sizeof text, "the period-2T branch from %s = %.12g ends here", o.parameter.c_str(), from);
        d.branch.started = true;
        d.branch.message = text;
      } else {
        d.branch = TraceDoubledBranch(problem, s, bif, options);
        if (d.branch.branch)
          for (const ContinuationPoint& p : d.branch.branch->points)
            d.reports.push_back(ReportPoint(model, o, problem, *d.branch.branch, p, 2));
      }
      b->doubled.push_back(std::move(d));
    }
    if (bif.type != BifurcationType::kNeimarkSacker || bif.Jump()) continue;
    TorusReport t{TorusFromNeimarkSacker(problem, s, bif, options, o.torus), std::nullopt, std::nullopt,
                  o.torus_periods};
    if (t.start.solved) {
      const Model here = WithParameters(model, {{o.parameter, t.start.parameter}});
      const double t_end = t.periods * 2 * M_PI / t.start.torus->frequencies()[0];
      t.validation = ValidateTorus(here, *t.start.torus, t_end, 2001);
      t.verdict = JudgeValidation(here, *t.start.torus, *t.validation, t_end, o.validate_tolerance);
    }
    b->tori.push_back(std::move(t));
  }
}

std::string Marks(const ContinuationSummary& s, const ContinuationPoint& p) {
  if (p.fold) return "  <- fold";
  if (p.bifurcation >= 0) return std::string("  <- ") + ShortName(s.bifurcations[p.bifurcation].type);
  return "";
}

std::string Header(const ContinuationSummary& c, bool validated, bool has_reference, bool torus) {
  char header[300];
  std::snprintf(header, sizeof header, "\n%-22s %-20s %-20s %-9s %s%-9s %-10s %-12s%s%s\n", c.parameter.c_str(),
                "frequency", "amplitude max|x|", "residual", torus ? "outermost w2/w1               " : "",
                "stability", "by", torus ? "max exponent" : "max|mu|", validated ? " validation" : "",
                has_reference ? " exact error" : "");
  return header;
}

std::string Row(const ContinuationSummary& c, const ContinuationPoint& p, const BranchPointReport& r,
                bool validated, bool has_reference) {
  std::string w;
  char text[300];
  for (double v : p.solution.frequencies()) {
    std::snprintf(text, sizeof text, "%s%.15g", w.empty() ? "" : ",", v);
    w += text;
  }
  std::string row;
  if (std::isnan(r.outermost)) {
    std::snprintf(text, sizeof text, "%-22.15g %-20s %-20.15g %-9.1e %-9s %-10s %-12.9g", p.parameter, w.c_str(),
                  r.peak, p.residual, r.stability.c_str(), ToString(p.stability_method), p.max_multiplier);
  } else {
    const bool lyapunov = r.lyapunov && r.lyapunov->ok;
    std::snprintf(text, sizeof text, "%-22.15g %-20s %-20.15g %-9.1e %-9.1e %-20.15g %-9s %-10s %-12.4g", p.parameter,
                  w.c_str(), r.peak, p.residual, r.outermost, r.ratio, r.stability.c_str(),
                  lyapunov ? "lyapunov" : "none", lyapunov ? r.lyapunov->max_exponent : NAN);
  }
  row = text;
  if (validated) std::snprintf(text, sizeof text, " %-10.1e", r.validation_error), row += text;
  if (has_reference) std::snprintf(text, sizeof text, " %.1e", r.reference_error()), row += text;
  return row + Marks(c, p) + (r.physical() ? "" : "  <- NON-PHYSICAL") + "\n";
}

std::string Table(const ContinuationSummary& c, const std::vector<BranchPointReport>& reports, bool validated,
                  bool has_reference) {
  const bool torus = !reports.empty() && !std::isnan(reports[0].outermost);
  std::string out = Header(c, validated, has_reference, torus);
  for (size_t i = 0; i < c.points.size(); ++i) out += Row(c, c.points[i], reports[i], validated, has_reference);
  return out;
}

// The stability lines: why unknown, how the methods compared, and the
// located bifurcations.
std::string StabilityLines(const ContinuationSummary& c, bool folds) {
  std::string out;
  if (!c.stability_note.empty()) out += "stability unknown at some points: " + c.stability_note + "\n";
  if (!c.stability_cross_check.empty()) out += "stability cross-check: " + c.stability_cross_check + "\n";
  for (const BifurcationPoint& b : c.bifurcations)
    if (folds || b.type != BifurcationType::kFold) out += b.Describe(c.parameter) + "\n";
  return out;
}

json BifurcationJson(const BifurcationPoint& b) {
  json out = {{"type", ToString(b.type)},          {"parameter", JsonNumber(b.parameter)},
              {"point", b.point},                  {"method", b.method},
              {"located", b.located},              {"tolerance", JsonNumber(b.tolerance)},
              {"distance", JsonNumber(b.distance)}, {"parameter_bracket", JsonNumber(b.parameter_bracket)},
              {"parameter_error", JsonNumber(b.parameter_error)}, {"iterations", b.iterations}};
  if (b.type != BifurcationType::kFold || b.multiplier != 0.0) {
    out["multiplier"] = {JsonNumber(b.multiplier.real()), JsonNumber(b.multiplier.imag())};
    out["multiplier_modulus"] = JsonNumber(std::abs(b.multiplier));
  }
  if (b.type == BifurcationType::kNeimarkSacker && !b.Jump()) out["torus_frequency"] = JsonNumber(b.torus_frequency);
  out["jump"] = b.Jump();
  return out;
}

json LyapunovJson(const TorusStabilityReport& l) {
  json exponents = json::array();
  for (double v : l.exponents) exponents.push_back(JsonNumber(v));
  return {{"ok", l.ok},         {"message", l.message},
          {"exponents", exponents}, {"trivial", l.trivial},
          {"trivial_max", JsonNumber(l.trivial_max)}, {"max_exponent", JsonNumber(l.max_exponent)},
          {"tolerance", JsonNumber(l.tolerance)},     {"spread", JsonNumber(l.spread)},
          {"stability", ToString(l.stability)},     {"time", JsonNumber(l.time)},
          {"steps", l.steps},                       {"seconds", l.seconds}};
}

json PointJson(const ContinuationSummary& c, const ContinuationPoint& p, const BranchPointReport& r, bool validated,
               bool has_reference) {
  json w = json::array();
  for (double v : p.solution.frequencies()) w.push_back(JsonNumber(v));
  json point = {{"parameter", JsonNumber(p.parameter)}, {"frequencies", w},
                {"amplitude", JsonNumber(r.peak)},      {"residual", JsonNumber(p.residual)},
                {"iterations", p.iterations},          {"arclength", JsonNumber(p.arclength)},
                {"fold", p.fold},                      {"stability", r.stability},
                {"stability_method", ToString(p.stability_method)}};
  if (p.stability_method != StabilityMethod::kNone) {
    point["max_multiplier"] = JsonNumber(p.max_multiplier);
    point["neutral_band"] = JsonNumber(p.neutral_band);
    point["multipliers"] = JsonComplex(p.multipliers);
    point["trivial_multiplier"] = p.trivial_multiplier;
  }
  if (p.bifurcation >= 0) point["bifurcation"] = ToString(c.bifurcations[p.bifurcation].type);
  if (validated) point["validation_error"] = JsonNumber(r.validation_error);
  if (has_reference)
    point["reference"] = {{"frequency_error", JsonNumber(r.frequency_error)},
                          {"amplitude_error", JsonNumber(r.amplitude_error)}};
  if (!std::isnan(r.outermost)) {
    point["outermost"] = JsonNumber(r.outermost);
    point["ratio"] = JsonNumber(r.ratio);
    point["stretch"] = r.segment;
  }
  if (const auto& l = r.lyapunov) point["lyapunov"] = LyapunovJson(*l);
  if (const auto& d = r.definitions) {
    point["physical"] = d->physical;
    point["definition_error"] = JsonNumber(d->error);
    point["definition_worst"] = d->worst_variable;
  }
  return point;
}

json PointsJson(const ContinuationSummary& c, const std::vector<BranchPointReport>& reports, bool validated,
                bool has_reference) {
  json points = json::array();
  for (size_t i = 0; i < c.points.size(); ++i)
    points.push_back(PointJson(c, c.points[i], reports[i], validated, has_reference));
  return points;
}

json TongueJson(const TongueReport& t) {
  json locked = json::array();
  for (const ContinuationSummary& l : t.locked) {
    json points = json::array();
    for (const ContinuationPoint& p : l.points)
      points.push_back({{"parameter", JsonNumber(p.parameter)}, {"amplitude", JsonNumber(PeakValue(p.solution))},
                        {"residual", JsonNumber(p.residual)}, {"fold", p.fold},
                        {"stability", ToString(p.stability)}, {"max_multiplier", JsonNumber(p.max_multiplier)}});
    locked.push_back({{"status", ToString(l.status)}, {"message", l.message}, {"points", points}});
  }
  return {{"p", t.lock.p},
          {"q", t.lock.q},
          {"crossed", t.crossed},
          {"message", t.message},
          {"torus_end", JsonNumber(t.torus_end)},
          {"ratio_end", JsonNumber(t.ratio_end)},
          {"centre_estimate", JsonNumber(t.centre_estimate)},
          {"locked_start", t.locked_start},
          {"near_edge", JsonNumber(t.near_edge)},
          {"far_edge", JsonNumber(t.far_edge)},
          {"resumed_at", JsonNumber(t.resumed_at)},
          {"locked", locked}};
}

json TorusJson(const TorusReport& t) {
  json out = {{"solved", t.start.solved},
              {"message", t.start.message},
              {"bifurcation_parameter", JsonNumber(t.start.bifurcation_parameter)},
              {"w2_at_bifurcation", JsonNumber(t.start.w2_at_bifurcation)},
              {"critical_mode_residual", JsonNumber(t.start.critical_mode_residual)},
              {"iterations", t.start.iterations},
              {"seconds", t.start.seconds}};
  if (!t.start.solved) return out;
  json w = json::array();
  for (double v : t.start.torus->frequencies()) w.push_back(JsonNumber(v));
  out["parameter"] = JsonNumber(t.start.parameter);
  out["frequencies"] = w;
  out["residual"] = JsonNumber(t.start.residual);
  out["theta2_amplitude"] = JsonNumber(t.start.theta2_amplitude);
  out["theta2_tail"] = JsonNumber(t.start.theta2_tail);
  out["periodic_side"] = t.start.periodic_side;
  out["solution"] = SolutionJson(*t.start.torus);
  if (t.validation)
    out["validation"] = {{"integrator", t.validation->integrator},
                         {"periods", t.periods},
                         {"max_error", JsonNumber(t.validation->max_error)},
                         {"relative_error", JsonNumber(t.verdict->relative_error)},
                         {"tolerance", JsonNumber(t.verdict->tolerance)},
                         {"status", t.verdict->ok ? "ok" : "exceeds"}};
  return out;
}

}  // namespace

double PeakValue(const HarmonicSolution& s, int variable) {
  if (s.frequencies().size() == 1) return s.Amplitude(variable);
  const double w = *std::min_element(s.frequencies().begin(), s.frequencies().end());
  const double span = 200 * 2 * M_PI / w;
  double peak = 0;
  for (int i = 0; i < 20000; ++i) peak = std::max(peak, std::abs(s.Value(variable, span * i / 20000)));
  return peak;
}

double BranchPointReport::reference_error() const {
  return std::isnan(frequency_error)   ? std::abs(amplitude_error)
         : std::isnan(amplitude_error) ? std::abs(frequency_error)
                                       : std::max(std::abs(frequency_error), std::abs(amplitude_error));
}

const char* ToString(BranchStatus status) {
  switch (status) {
    case BranchStatus::kCompleted: return "completed";
    case BranchStatus::kStopped: return "stopped";
    case BranchStatus::kNonPhysical: return "non_physical";
    case BranchStatus::kSwitchFailed: return "switch_failed";
  }
  return "unknown";
}

std::string ContinueOptions::IsValid() const {
  if (parameter.empty()) return "continuation: no parameter named";
  if (!std::isfinite(from) || !std::isfinite(to)) return "continuation: the range must be finite";
  if (from == to) return "continuation: the range is empty (from = to)";
  if (steps < 1) return "continuation: steps must be >= 1";
  if (!(max_step >= 0) || !std::isfinite(max_step)) return "continuation: max_step must be finite and >= 0";
  if (validate_periods < 1) return "continuation: validate_periods must be >= 1";
  if (stability_method == StabilityMethod::kNone) return "continuation: stability_method none (set stability = false)";
  if (switch_branches && !stability) return "continuation: switching branches needs the stability per point";
  if (switch_branches && natural) return "continuation: switching branches follows them by pseudo-arclength";
  if (!(torus_periods > 0) || !(validate_tolerance > 0)) return "continuation: torus_periods and validate_tolerance must be > 0";
  if (const std::string why = torus.IsValid(); !why.empty()) return "continuation: torus: " + why;
  if (!(tail_tolerance > 0)) return "continuation: tail_tolerance must be > 0";
  if (max_enrichments < 0 || max_order_raises < 0) return "continuation: max_enrichments and max_order_raises must be >= 0";
  if (max_denominator < 1 || max_tongues < 0) return "continuation: max_denominator must be >= 1, max_tongues >= 0";
  if (const std::string why = torus_stability.IsValid(); !why.empty()) return "continuation: torus stability: " + why;
  return "";
}

bool BranchSummary::switch_failed() const {
  for (const DoubledBranchReport& d : doubled)
    if (!d.branch.started) return true;
  for (const TorusReport& t : tori)
    if (!t.start.solved) return true;
  return false;
}

namespace {

// Tori (METHOD.md s.18): the trace stops where the basis given no longer
// resolves the torus (its outermost coefficients exceed the tolerance).
constexpr const char* kUnresolved = "the basis no longer resolves the torus";
std::function<std::string(const ContinuationPoint&)> TailWatch(double tolerance) {
  return [tolerance](const ContinuationPoint& p) -> std::string {
    const double tail = OutermostCoefficients(p.solution);
    if (tail <= tolerance) return "";
    const auto& w = p.solution.frequencies();
    char text[300];
    std::snprintf(text, sizeof text,
                  "the outermost coefficients reach %.2e of the solution (> tail tolerance %.1e): %s (w2/w1 = "
                  "%.10g)",
                  tail, tolerance, kUnresolved, w[1] / w[0]);
    return text;
  };
}

// A periodic branch with an accuracy target (ContinueOptions::max_order_raises):
// stops where a point's coefficient-tail estimate (EstimateTruncation without
// calibration: no lower order at hand per point) exceeds `threshold`.
constexpr const char* kOrderShort = "the order no longer meets the accuracy target";
std::function<std::string(const ContinuationPoint&)> OrderWatch(double threshold, DecayModel decay) {
  return [threshold, decay](const ContinuationPoint& p) -> std::string {
    const double estimate = EstimateTruncation(p.solution, nullptr, decay).state;
    if (estimate <= threshold) return "";
    char text[300];
    std::snprintf(text, sizeof text, "the coefficient tail estimates %.2e (> %.1e) at order %d: %s", estimate,
                  threshold, p.solution.basis().order(), kOrderShort);
    return text;
  };
}

// The watch's threshold on the tail estimate for a stretch that starts on
// `first`, whose order selection estimated `estimate` (calibrated; <= 0 when
// unknown): a quarter of the target (the margin NextOrder aims at: the
// calibration's constant drifts along a branch, a Duffing branch ended
// 2.3e-10 from CVODE with the full target) scaled by first's ratio of tail to
// estimate (that constant carried along the stretch), and at least twice
// first's own tail, so that the watch fires on a change along the branch,
// not at its start.
constexpr double kWatchMargin = 0.25;
double WatchThreshold(const HarmonicSolution& first, double estimate, double target, DecayModel decay) {
  const double tail = EstimateTruncation(first, nullptr, decay).state;
  const double scaled = estimate > 0 && tail > 0 ? target * tail / estimate : target;
  return std::max(kWatchMargin * scaled, 2 * tail);
}

// Where the locked orbit is first sought: the beat Omega = q w2 - p w1
// vanishes at the tongue's edges; near them Omega^2 is close to a quadratic
// in the parameter (Adler's phase equation: Omega^2 = (lambda - c)^2 - a^2,
// edges c -+ a), so the last three points give the centre c and the near
// edge. Accepted when that edge lies ahead, before `end`: else NaN.
double TongueCentre(const std::vector<ContinuationPoint>& points, const Resonance& lock, double direction,
                    double end) {
  const int n = static_cast<int>(points.size());
  if (n < 3) return NAN;
  auto beat2 = [&](int i) {
    const auto& w = points[i].solution.frequencies();
    return std::pow(lock.q * w[1] - lock.p * w[0], 2);
  };
  // In u = lambda - lambda_last (no cancellation): Omega^2 = a u^2 + b u + c.
  const double x2 = points[n - 1].parameter;
  const double u0 = points[n - 3].parameter - x2, u1 = points[n - 2].parameter - x2;
  const double d01 = (beat2(n - 2) - beat2(n - 3)) / (u1 - u0), d12 = (beat2(n - 1) - beat2(n - 2)) / (-u1);
  const double a = (d12 - d01) / (-u0), b = d01 - a * (u0 + u1), c = beat2(n - 1);
  const double discriminant = b * b - 4 * a * c;
  if (!(a > 0) || !(discriminant > 0)) return NAN;
  const double centre = -b / (2 * a), half_width = std::sqrt(discriminant) / (2 * a);
  const double near_edge = centre - direction * half_width;  // relative to x2
  return direction * near_edge > 0 && direction * (x2 + near_edge - end) < 0 ? x2 + centre : NAN;
}

// The resonance the stopped torus is meeting: the smallest q whose tongue
// TongueCentre places ahead (the widest: tongues narrow fast with q).
bool NearestTongue(const std::vector<ContinuationPoint>& points, int max_denominator, double direction, double end,
                   TongueReport* t) {
  for (int q = 1; q <= max_denominator; ++q) {
    const Resonance lock{static_cast<int>(std::lround(t->ratio_end * q)), q, 0};
    if (lock.p < 1) continue;
    const double centre = TongueCentre(points, lock, direction, end);
    if (std::isnan(centre)) continue;
    t->lock = lock;
    t->lock.distance = std::abs(t->ratio_end - static_cast<double>(lock.p) / q);
    t->centre_estimate = centre;
    return true;
  }
  return false;
}

// The periodic harmonic balance options for the locked orbit: the order
// that holds the torus' harmonics m q + n p.
HarmonicBalanceOptions LockedOptions(const HarmonicBalanceOptions& torus, int order) {
  HarmonicBalanceOptions o = torus;
  o.order = order;
  o.basis_for_order = nullptr;
  o.shape = BasisShape::kDiamond;
  o.samples.clear();
  o.tolerance = 0;
  return o;
}

// The first fold of a locked trace: a tongue's edge (NaN: none).
double FirstFold(const ContinuationSummary& s) {
  for (const ContinuationPoint& p : s.points)
    if (p.fold) return p.parameter;
  return NAN;
}

// The locked branch from inside the tongue (at t->centre_estimate) toward
// the near end and the far end; the edges are its folds.
bool TraceLockedBranch(const Model& model, const ContinueOptions& o, const ContinuationOptions& options,
                       const ContinuationPoint& last, TongueReport* t) {
  const Resonance lock = t->lock;
  auto locked_at = [&model, name = o.parameter, lock](double v) {
    return LockedModel(WithParameters(model, {{name, v}}), lock);
  };
  ContinuationOptions locked = options;
  // Across a tongue the locked orbit's phase turns by ~pi: its coefficients,
  // not the parameter, make the arclength; steps in proportion.
  locked.max_step = std::abs(o.to - o.from);
  locked.initial_step = locked.max_step / 20;
  locked.harmonic_balance =
      LockedOptions(o.harmonic_balance, LockedSolution(last.solution, lock, 0.0).basis().order());
  // Inside the tongue the torus carries the locked orbits: the torus at the
  // rotation number p/q, its second angle turned by a phase, is a guess;
  // a few phases, until one converges to an orbit of the torus' size (not,
  // e.g., the small unstable orbit inside it).
  const Model model_in = locked_at(t->centre_estimate);
  const double peak = PeakValue(last.solution);
  std::optional<HarmonicSolution> start;
  std::string why;
  for (int j = 0; j < 8 && !start; ++j) {
    const HarmonicBalanceSummary s = SolveHarmonicBalance(
        model_in.problem, LockedSolution(last.solution, lock, 2 * M_PI * j / 8), locked.harmonic_balance);
    if (s.usable() && std::abs(PeakValue(*s.solution) - peak) <= 0.2 * peak) start = s.solution;
    why = s.usable() ? "an orbit of another size" : s.BriefReport();
    t->locked_start = "torus at p/q, phase " + std::to_string(j) + "/8";
  }
  if (!start) {
    t->message = "no locked orbit near the torus at " + o.parameter + " = " + std::to_string(t->centre_estimate) +
                 " from 8 phases (last: " + why + ")";
    t->locked_start.clear();
    return false;
  }
  for (double end : {last.parameter, o.to}) {
    const ContinuationProblem problem = ModelContinuationProblem(locked_at, o.parameter, t->centre_estimate, end);
    t->locked.push_back(TraceBranch(problem, *start, locked));
  }
  t->near_edge = FirstFold(t->locked[0]);
  t->far_edge = FirstFold(t->locked[1]);
  if (std::isnan(t->near_edge)) t->message = "the locked branch has no fold toward the torus side: " + t->locked[0].message;
  if (std::isnan(t->far_edge))
    t->message = t->locked[1].completed() ? "locked to the end of the range" : "the locked branch has no far fold: " + t->locked[1].message;
  return std::isfinite(t->near_edge) && std::isfinite(t->far_edge);
}

// The torus past the far edge, as far from it as the last torus was from the
// near one (farther while its outermost coefficients are too large): from
// the last torus with its rotation number mirrored about p/q, else the
// automatic start.
std::optional<HarmonicSolution> ResumeTorus(const Model& model, const ContinueOptions& o,
                                            const ContinuationPoint& last, TongueReport* t) {
  const double direction = o.to > o.from ? 1 : -1;
  double distance = std::max(std::abs(last.parameter - t->near_edge), 1e-4 * std::abs(o.to - o.from));
  // The beat q w2 - p w1 changes sign across the tongue: its mirror image.
  const auto& w_end = last.solution.frequencies();
  const double beat = t->lock.q * w_end[1] - t->lock.p * w_end[0];
  std::string why;
  for (int attempt = 0; attempt < 5; ++attempt, distance *= 1.5) {
    double at = t->far_edge + direction * distance;
    if (direction * (at - o.to) > 0) {
      if (attempt > 0 && direction * (t->far_edge + direction * distance / 1.5 - o.to) >= 0) break;
      at = o.to;
    }
    const Model here = WithParameters(model, {{o.parameter, at}});
    // A forced torus' w1 is the forcing at `at`; an autonomous one's, its last value.
    const double w1 = IsForcedTorus(here) ? here.problem.frequencies[0] : w_end[0];
    const HarmonicSolution guess = last.solution.WithFrequencies({w1, (t->lock.p * w1 - beat) / t->lock.q});
    const StartedSolve s = SolveFromAnyStart(here, guess, o.harmonic_balance);
    if (s.summary.usable()) {
      const double tail = OutermostCoefficients(*s.summary.solution);
      if (tail <= o.tail_tolerance) {
        t->resumed_at = at;
        return s.summary.solution;
      }
      why = "outermost coefficients " + std::to_string(tail) + " at " + std::to_string(at);
    } else {
      why = s.summary.BriefReport() + " at " + std::to_string(at);
    }
    if (at == o.to) break;
  }
  t->message = "no resolved torus found past the far edge before the end of the range (last: " + why + ")";
  return std::nullopt;
}

// Across the tongue the torus stopped at: the locked branch, its edges,
// and the torus past it (nullopt when the branch ends here).
std::optional<HarmonicSolution> CrossTongue(const Model& model, const ContinueOptions& o,
                                            const ContinuationOptions& options, const ContinuationSummary& s,
                                            TongueReport* t) {
  const ContinuationPoint& last = s.points.back();
  const auto& w = last.solution.frequencies();
  t->torus_end = last.parameter;
  t->ratio_end = w[1] / w[0];
  if (!NearestTongue(s.points, o.max_denominator, o.to > o.from ? 1 : -1, o.to, t)) {
    t->lock = NearestResonance(t->ratio_end, o.max_denominator);
    t->message = "no locking tongue ahead (the beat q w2 - p w1 of no q <= " + std::to_string(o.max_denominator) +
                 " falls toward 0 there): the basis, not a resonance, limits the torus; raise the order";
    return std::nullopt;
  }
  if (!TraceLockedBranch(model, o, options, last, t)) return std::nullopt;
  std::optional<HarmonicSolution> resumed = ResumeTorus(model, o, last, t);
  t->crossed = resumed.has_value();
  return resumed;
}

// Appends a later stretch of the branch to the first (a torus past an
// enrichment or a tongue, a periodic orbit past an order raise), with its
// bifurcations and counts; `order` and `samples` stay the first stretch's.
void AppendStretch(ContinuationSummary stretch, ContinuationSummary* branch) {
  const double offset = branch->arclength;
  const int first_point = static_cast<int>(branch->points.size());
  const int first_bifurcation = static_cast<int>(branch->bifurcations.size());
  for (ContinuationPoint& p : stretch.points) {
    p.arclength += offset;
    p.folds_before += branch->num_folds;
    if (p.bifurcation >= 0) p.bifurcation += first_bifurcation;
    branch->points.push_back(std::move(p));
  }
  for (BifurcationPoint& b : stretch.bifurcations) {
    b.point += first_point;
    branch->bifurcations.push_back(std::move(b));
  }
  branch->num_folds += stretch.num_folds;
  branch->hill_points += stretch.hill_points;
  branch->monodromy_points += stretch.monodromy_points;
  branch->harmonic_monodromy_points += stretch.harmonic_monodromy_points;
  branch->stability_seconds += stretch.stability_seconds;
  branch->status = stretch.status;
  branch->message = stretch.message;
  branch->accepted_steps += stretch.accepted_steps;
  branch->rejected_steps += stretch.rejected_steps;
  branch->corrector_iterations += stretch.corrector_iterations;
  branch->arclength += stretch.arclength;
  branch->seconds += stretch.seconds;
}

}  // namespace

namespace {

// The torus at `last`'s parameter (the trace's own problem there, no rebuild
// of the model) on the adaptive index set enriched from `last`
// (SelectIndexSet starts from its set), when its outermost
// coefficients are then within the tail tolerance; nullopt otherwise or
// when the trace is not on the adaptive set.
std::optional<HarmonicSolution> Enriched(const ContinuationProblem& problem, const ContinueOptions& o,
                                         const ContinuationPoint& last) {
  const HarmonicBalanceOptions& h = o.harmonic_balance;
  if (h.shape != BasisShape::kAdaptive || !(h.tolerance > 0)) return std::nullopt;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(problem.build(last.parameter), last.solution, h);
  if (!s.usable() || s.solution->basis().size() <= last.solution.basis().size() ||
      OutermostCoefficients(*s.solution) > o.tail_tolerance)
    return std::nullopt;
  return s.solution;
}

// The periodic orbit at `last`'s parameter with its order selected again for
// the target, warm from `last` (METHOD.md s.8 and s.15): a higher order, or
// the same one with its estimate measured again (the watch then starts from
// it); nullopt, saying why, when that selection fails or stops short (a hard
// target).
std::optional<HarmonicBalanceSummary> Reselected(const ContinuationProblem& problem, const ContinueOptions& o,
                                                 const ContinuationPoint& last, std::string* why) {
  HarmonicBalanceOptions h = o.harmonic_balance;
  h.order = last.solution.basis().order();
  HarmonicBalanceSummary s = SolveHarmonicBalance(problem.build(last.parameter), last.solution, h);
  if (s.usable()) return s;
  *why = "the order selection there: " + s.solver.message;
  return std::nullopt;
}

// The branch, and its reports. A torus' trace stops where the basis no
// longer resolves it; on the adaptive index set the set is enriched there
// and the trace goes on (Enriched); otherwise a torus (forced, or
// autonomous with both frequencies unknown) is taken across the locking
// tongue (CrossTongue) and traced on past it, stretch by stretch.
void TraceModelBranch(const Model& model, const ContinueOptions& o, ContinuationProblem problem,
                      const ContinuationOptions& options, HarmonicSolution first, double first_estimate,
                      BranchSummary* b) {
  const bool torus = b->bases > 1;
  const double target = o.harmonic_balance.tolerance;
  const DecayModel decay = DecayFor(model.problem.system);
  if (torus)
    problem.stop_when = TailWatch(o.tail_tolerance);
  else if (target > 0)
    problem.stop_when = OrderWatch(WatchThreshold(first, first_estimate, target, decay), decay);
  // After an order raise the trace resumes at the raise's point along the
  // branch's chord there (it may be heading away from `end`, past a fold).
  std::optional<std::pair<double, HarmonicSolution>> resume;
  // Each watch's firing selects the order again; the threshold doubles the
  // tail at least, so a branch sees few (a cap against a tail that grows
  // without bound).
  constexpr int kMaxReselections = 32;
  int reselections = 0;
  for (int stretch = 0;; ++stretch) {
    ContinuationSummary s = resume ? TraceBranchFrom(problem, resume->first, first, resume->second, options)
                                   : TraceBranch(problem, first, options);
    resume.reset();
    const size_t before = stretch == 0 ? 0 : b->continuation.points.size();
    if (stretch == 0)
      b->continuation = std::move(s);
    else
      AppendStretch(std::move(s), &b->continuation);
    const ContinuationSummary& c = b->continuation;
    for (size_t i = before; i < c.points.size(); ++i) {
      b->reports.push_back(ReportPoint(model, o, problem, c, c.points[i]));
      b->reports.back().segment = stretch;
    }
    // A torus' stability is its Lyapunov exponents (the report's), not the
    // Floquet multipliers the trace looks for.
    if (torus && o.stability) b->continuation.stability_note.clear();
    const bool stopped = c.status == ContinuationStatus::kStopped || c.status == ContinuationStatus::kStepTooSmall;
    // Only the watcher set above stops a trace (kStopped): TailWatch on a
    // torus (the basis no longer resolves it), OrderWatch on a periodic
    // branch with a target (the order no longer meets it).
    const bool watched = c.status == ContinuationStatus::kStopped;
    if (torus && watched &&
        static_cast<int>(b->enrichments.size()) < o.max_enrichments) {
      if (std::optional<HarmonicSolution> richer = Enriched(problem, o, c.points.back())) {
        b->enrichments.push_back({c.points.back().parameter, c.points.back().solution.basis().size(),
                                  richer->basis().size()});
        // The richer solution replaces the last point: the next stretch starts on it.
        b->continuation.points.pop_back();
        b->reports.pop_back();
        problem.start = b->enrichments.back().parameter;
        first = *richer;
        continue;
      }
    }
    if (!torus && watched && c.points.size() >= 2 &&
        static_cast<int>(b->order_raises.size()) < o.max_order_raises && ++reselections <= kMaxReselections) {
      std::string why;
      const ContinuationPoint& last = c.points.back();
      if (std::optional<HarmonicBalanceSummary> selected = Reselected(problem, o, last, &why)) {
        const int before_order = last.solution.basis().order();
        if (selected->order > before_order) b->order_raises.push_back({last.parameter, before_order, selected->order});
        const HarmonicBasis& basis = selected->solution->basis();
        const ContinuationPoint& previous = c.points[c.points.size() - 2];
        HarmonicSolution chord = last.solution.OnBasis(basis);
        chord = HarmonicSolution(basis, chord.frequencies(),
                                 chord.coefficients() - previous.solution.OnBasis(basis).coefficients(),
                                 chord.variables());
        resume.emplace(last.parameter, std::move(chord));
        // The reselected solution replaces the last point.
        b->continuation.points.pop_back();
        b->reports.pop_back();
        first = *selected->solution;
        problem.stop_when = OrderWatch(WatchThreshold(first, selected->state_estimate, target, decay), decay);
        continue;
      }
      b->continuation.message += "; " + why;
    }
    if (!torus || !stopped || !o.locking || !(IsForcedTorus(model) || IsAutonomousTorus(model)) ||
        stretch >= o.max_tongues ||
        c.points.size() - before < 2)
      return;
    TongueReport t;
    const std::vector<ContinuationPoint> last(c.points.begin() + static_cast<long>(before), c.points.end());
    ContinuationSummary tail = c;
    tail.points = last;
    std::optional<HarmonicSolution> resumed = CrossTongue(model, o, options, tail, &t);
    b->tongues.push_back(std::move(t));
    if (!resumed) {
      if (b->tongues.back().message == "locked to the end of the range") {
        b->continuation.status = ContinuationStatus::kCompleted;
        b->continuation.message = "locked from " + o.parameter + " = " +
                                  std::to_string(b->tongues.back().near_edge) + " to the end of the range";
      }
      return;
    }
    problem.start = b->tongues.back().resumed_at;
    first = *resumed;
  }
}

// A torus branch's first point judged by Hill's method too (METHOD.md
// s.18), as periodic branches cross-check Hill and the monodromy: how well
// the two agree and what each costs. Skipped above kTorusCrossCheckRows rows
// of the Hill matrix (its dense LU: ~0.5 s at 2400, ~5 s at 4500).
constexpr int kTorusCrossCheckRows = 2500;
std::string TorusCrossCheck(const Model& model_at_first, const HarmonicSolution& first,
                            const TorusStabilityReport& lyapunov) {
  const long rows = static_cast<long>(first.num_variables()) * first.basis().num_coefficients();
  char text[400];
  if (rows > kTorusCrossCheckRows) {
    std::snprintf(text, sizeof text, "Hill's method on the torus skipped (%ld rows > %d)", rows, kTorusCrossCheckRows);
    return text;
  }
  const StabilitySummary s = TorusStabilityFrom(model_at_first.problem, first, lyapunov);
  if (!s.hill) return s.hill_note;
  char compared[120] = "the trajectory left the torus: exponents not compared";
  if (s.max_exponent_difference)
    std::snprintf(compared, sizeof compared, "exponents agree to %.1e (Lyapunov tolerance %.1e)",
                  *s.max_exponent_difference, lyapunov.tolerance);
  std::snprintf(text, sizeof text,
                "Hill %.3g ms (%d rows, largest Re(lambda) %.6g, %s), Lyapunov %.3g ms at the first point; %s, "
                "verdicts %s",
                1e3 * s.hill->seconds, s.hill->size, s.hill->max_real_part, ToString(s.hill_verdict),
                1e3 * lyapunov.seconds, compared, s.agree() ? "agree" : "DISAGREE");
  return text;
}

}  // namespace

BranchSummary ContinueModel(const Model& model, const HarmonicSolution& guess, const ContinueOptions& o) {
  if (const std::string error = o.IsValid(); !error.empty()) throw std::invalid_argument(error);
  // Both ends must be values the model accepts (bad input, not a failed step).
  const Model start = WithParameters(model, {{o.parameter, o.from}});
  try {
    WithParameters(model, {{o.parameter, o.to}});
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("at the end of the range: ") + e.what());
  }
  const ContinuationProblem problem = ModelContinuationProblem(model, o.parameter, o.from, o.to);
  const ContinuationOptions options = TraceOptions(o);
  // The first point from the automatic start, so that a model file without
  // a guess can be traced.
  const StartedSolve started = SolveFromAnyStart(start, guess, o.harmonic_balance);
  if (!started.summary.usable() && model.original_equations) {
    // As SolveModel: the recast's auxiliaries failed, the equations as written may not.
    const Model original = OriginalEquationsOf(model);
    BranchSummary b = ContinueModel(original, GuessAtOrder(original, o.harmonic_balance.order), o);
    b.start_route += " on the original equations (the recast reached no physical solution at the start)";
    return b;
  }
  BranchSummary b;
  b.start_route = started.route;
  b.has_reference = start.reference.has_frequency() || start.reference.has_amplitude();
  b.validated = o.validate;
  b.bases = static_cast<int>(start.problem.frequencies.size());
  const bool usable = started.summary.usable();
  TraceModelBranch(model, o, problem, options, usable ? *started.summary.solution : guess,
                   usable ? started.summary.state_estimate : -1, &b);
  if (b.bases > 1 && !b.reports.empty() && b.reports[0].lyapunov && b.reports[0].lyapunov->ok)
    b.continuation.stability_cross_check =
        TorusCrossCheck(start, b.continuation.points[0].solution, *b.reports[0].lyapunov);  // the first point is at o.from
  for (size_t i = 0; i < b.continuation.points.size(); ++i)
    if (!b.reports[i].physical()) b.non_physical.push_back(i);
  b.switched = o.switch_branches;
  if (o.switch_branches) SwitchBranches(model, o, problem, options, &b);
  const ContinuationStatus status = b.continuation.status;
  b.message = b.continuation.message;
  b.status = !(b.continuation.completed() || status == ContinuationStatus::kLeftRange) ? BranchStatus::kStopped
             : !b.non_physical.empty()                                                  ? BranchStatus::kNonPhysical
             : b.switch_failed()                                                        ? BranchStatus::kSwitchFailed
                                                                                        : BranchStatus::kCompleted;
  if (b.status == BranchStatus::kSwitchFailed) b.message = "a branch switch failed (see the switched branches)";
  return b;
}

namespace {

// A torus branch's adequacy and stability in two lines: the largest
// outermost coefficients, and the Lyapunov verdicts with their cost.
std::string TorusLines(const ContinuationSummary& c, const std::vector<BranchPointReport>& reports) {
  if (reports.empty() || std::isnan(reports[0].outermost)) return "";
  double worst = 0, seconds = 0, tolerance = 0, trivial = 0;
  int counts[4] = {0, 0, 0, 0}, computed = 0;
  long steps = 0;
  for (const BranchPointReport& r : reports) {
    worst = std::max(worst, r.outermost);
    if (!r.lyapunov || !r.lyapunov->ok) continue;
    ++computed;
    ++counts[static_cast<int>(r.lyapunov->stability)];
    seconds += r.lyapunov->seconds;
    steps += r.lyapunov->steps;
    tolerance = std::max(tolerance, r.lyapunov->tolerance);
    trivial = std::max(trivial, r.lyapunov->trivial_max);
  }
  char text[500];
  std::snprintf(text, sizeof text, "tori: outermost coefficients at most %.2e of the solution (first order %d)\n",
                worst, c.order);
  std::string out = text;
  if (computed > 0) {
    std::snprintf(text, sizeof text,
                  "tori: stability by Lyapunov exponents of the original equations at %d points: %d stable, %d "
                  "unstable, %d neutral, %d unknown (largest tolerance %.1e; trivial exponents at most %.1e); cost "
                  "%.3g ms and %ld CVODE steps per point\n",
                  computed, counts[static_cast<int>(PointStability::kStable)],
                  counts[static_cast<int>(PointStability::kUnstable)], counts[static_cast<int>(PointStability::kNeutral)],
                  counts[static_cast<int>(PointStability::kUnknown)], tolerance, trivial, 1e3 * seconds / computed,
                  steps / computed);
    out += text;
  }
  return out;
}

}  // namespace

std::string TongueReport::Describe(const std::string& parameter) const {
  char text[600];
  std::snprintf(text, sizeof text, "the torus stopped at %s = %.10g (w2/w1 = %.10g)", parameter.c_str(), torus_end,
                ratio_end);
  std::string out = text;
  if (std::isnan(centre_estimate)) return out + "; " + message;
  std::snprintf(text, sizeof text, "locking tongue %d:%d (w2/w1 = %d/%d): ", lock.p, lock.q, lock.p, lock.q);
  out = text + out;
  std::snprintf(text, sizeof text, "; locked orbit of base w1/%d solved at %.10g (%s)", lock.q, centre_estimate,
                locked_start.empty() ? "no start converged" : locked_start.c_str());
  out += text;
  if (std::isfinite(near_edge) && std::isfinite(far_edge)) {
    std::snprintf(text, sizeof text, "; locked between %s = %.12g and %.12g (folds of the locked branch)",
                  parameter.c_str(), std::min(near_edge, far_edge), std::max(near_edge, far_edge));
    out += text;
  }
  if (crossed) {
    std::snprintf(text, sizeof text, "; the torus resumed at %s = %.10g", parameter.c_str(), resumed_at);
    out += text;
  }
  if (!message.empty()) out += "; " + message;
  return out;
}

std::string BranchSummary::BriefReport() const { return continuation.BriefReport(); }

std::string BranchSummary::FullReport(bool table) const {
  std::string out = BriefReport() + "\n";
  if (start_route != "guess" && !start_route.empty()) out += "first point from the " + start_route + " start\n";
  if (!continuation.message.empty()) out += continuation.message + "\n";
  out += StabilityLines(continuation, true);
  out += TorusLines(continuation, reports);
  for (const Enrichment& e : enrichments) {
    char text[200];
    std::snprintf(text, sizeof text, "tori: index set enriched at %s = %.10g (%d -> %d harmonics)\n",
                  continuation.parameter.c_str(), e.parameter, e.before, e.after);
    out += text;
  }
  for (const Enrichment& e : order_raises) {
    char text[200];
    std::snprintf(text, sizeof text, "order raised for the target at %s = %.10g (%d -> %d)\n",
                  continuation.parameter.c_str(), e.parameter, e.before, e.after);
    out += text;
  }
  if (table) out += Table(continuation, reports, validated, has_reference);
  for (const TongueReport& t : tongues) {
    out += "\n" + t.Describe(continuation.parameter) + "\n";
    for (const ContinuationSummary& l : t.locked) {
      out += "  locked branch: " + l.BriefReport() + "\n";
      if (!l.message.empty()) out += "  " + l.message + "\n";
    }
  }
  for (const DoubledBranchReport& d : doubled) {
    char text[200];
    if (!d.branch.branch) {
      std::snprintf(text, sizeof text, "\nperiod doubling at %s = %.12g: ", continuation.parameter.c_str(),
                    d.from.parameter);
      out += text + d.branch.message + "\n";
      continue;
    }
    std::snprintf(text, sizeof text, "\nperiod-2T branch from the period doubling at %s = %.12g (critical mode |J v|/|J| = %.1e): ",
                  continuation.parameter.c_str(), d.from.parameter, d.branch.critical_mode_residual);
    out += text + d.branch.message + "\n";
    if (!d.branch.branch->message.empty()) out += d.branch.branch->message + "\n";
    out += StabilityLines(*d.branch.branch, true);
    if (table) out += Table(*d.branch.branch, d.reports, validated, false);
  }
  for (const TorusReport& t : tori) {
    out += "\n" + t.start.BriefReport() + "\n";
    if (t.validation) {
      char text[300];
      std::snprintf(text, sizeof text, "torus against %s over %g periods of w1: max error %.2e, %s\n",
                    t.validation->integrator.c_str(), t.periods, t.validation->max_error,
                    t.verdict->Describe().c_str());
      out += text;
    }
  }
  return out;
}

json BranchSummary::ToJson() const {
  const ContinuationSummary& c = continuation;
  json folds = json::array(), bifurcations = json::array();
  for (const ContinuationPoint& p : c.points)
    if (p.fold) folds.push_back(JsonNumber(p.parameter));
  for (const BifurcationPoint& b : c.bifurcations) bifurcations.push_back(BifurcationJson(b));
  json out = {{"parameter", c.parameter},
              {"range", {JsonNumber(c.start), JsonNumber(c.end)}},
              {"method", ToString(c.method)},
              {"status", ToString(c.status)},
              {"message", c.message},
              {"start", start_route},
              {"stability_note", c.stability_note},
              {"stability_points",
               {{"hill", c.hill_points},
                {"monodromy", c.monodromy_points},
                {"hb_monodromy", c.harmonic_monodromy_points},
                {"seconds", c.stability_seconds},
                {"cross_check", c.stability_cross_check}}},
              {"order", c.order},
              {"samples", c.samples.size() == 1 ? json(c.samples[0]) : json(c.samples)},
              {"points", c.points.size()},
              {"folds", folds},
              {"bifurcations", bifurcations},
              {"accepted_steps", c.accepted_steps},
              {"rejected_steps", c.rejected_steps},
              {"arclength", JsonNumber(c.arclength)},
              {"seconds", c.seconds},
              {"branch", PointsJson(c, reports, validated, has_reference)}};
  if (bases > 1) {
    json t = json::array();
    for (const TongueReport& tongue : tongues) t.push_back(TongueJson(tongue));
    out["tongues"] = t;
    json e = json::array();
    for (const Enrichment& enrichment : enrichments)
      e.push_back({{"parameter", enrichment.parameter}, {"before", enrichment.before}, {"after", enrichment.after}});
    out["enrichments"] = e;
  } else {
    json r = json::array();
    for (const Enrichment& raise : order_raises)
      r.push_back({{"parameter", raise.parameter}, {"before", raise.before}, {"after", raise.after}});
    out["order_raises"] = r;
  }
  if (!switched) return out;
  json doubled_json = json::array(), tori_json = json::array();
  for (const DoubledBranchReport& d : doubled) {
    json entry = {{"from", JsonNumber(d.from.parameter)}, {"started", d.branch.started},
                  {"message", d.branch.message}, {"critical_mode_residual", JsonNumber(d.branch.critical_mode_residual)}};
    if (const auto& branch = d.branch.branch) {
      json bifs = json::array();
      for (const BifurcationPoint& b : branch->bifurcations) bifs.push_back(BifurcationJson(b));
      entry["status"] = ToString(branch->status);
      entry["order"] = branch->order;
      entry["bifurcations"] = bifs;
      entry["branch"] = PointsJson(*branch, d.reports, validated, false);
    }
    doubled_json.push_back(entry);
  }
  for (const TorusReport& t : tori) tori_json.push_back(TorusJson(t));
  out["doubled_branches"] = doubled_json;
  out["tori"] = tori_json;
  return out;
}

}  // namespace rmhb

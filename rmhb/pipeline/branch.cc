#include "rmhb/pipeline/branch.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "rmhb/pipeline/monodromy.h"
#include "rmhb/pipeline/report.h"
#include "rmhb/pipeline/start.h"

namespace rmhb {
namespace {

using nlohmann::json;

// `period_multiple` 2 on a period-doubled branch: its solution has base w/2
// while the model's equations keep the forcing w; the reference and the
// definitions are the period-T model's and are not checked there.
BranchPointReport ReportPoint(const Model& model, const ContinueOptions& o, const ContinuationSummary& branch,
                              const ContinuationPoint& p, int period_multiple = 1) {
  BranchPointReport r;
  r.peak = PeakValue(p.solution);
  r.stability = ToString(p.stability);
  const Model here = WithParameters(model, {{o.parameter, p.parameter}});
  if (period_multiple == 1) {
    if (here.problem.definitions)
      r.definitions = CheckDefinitions(p.solution, here.problem.definitions, branch.samples);
    const ReferenceErrors errors = ErrorsAgainst(here.reference, p.solution);
    r.frequency_error = errors.frequency;
    r.amplitude_error = errors.amplitude;
  }
  if (o.validate) {
    const auto& w = p.solution.frequencies();
    const double t_end = o.validate_periods * 2 * M_PI / *std::min_element(w.begin(), w.end());
    integrators::ValidationReport v;
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
            d.reports.push_back(ReportPoint(model, o, *d.branch.branch, p, 2));
      }
      b->doubled.push_back(std::move(d));
    }
    if (bif.type != BifurcationType::kNeimarkSacker) continue;
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

std::string Header(const ContinuationSummary& c, bool validated, bool has_reference) {
  char header[256];
  std::snprintf(header, sizeof header, "\n%-22s %-20s %-20s %-9s %-9s %-10s %-12s%s%s\n", c.parameter.c_str(),
                "frequency", "amplitude max|x|", "residual", "stability", "by", "max|mu|",
                validated ? " validation" : "", has_reference ? " exact error" : "");
  return header;
}

std::string Row(const ContinuationSummary& c, const ContinuationPoint& p, const BranchPointReport& r,
                bool validated, bool has_reference) {
  std::string w;
  char text[256];
  for (double v : p.solution.frequencies()) {
    std::snprintf(text, sizeof text, "%s%.15g", w.empty() ? "" : ",", v);
    w += text;
  }
  std::snprintf(text, sizeof text, "%-22.15g %-20s %-20.15g %-9.1e %-9s %-10s %-12.9g", p.parameter, w.c_str(),
                r.peak, p.residual, r.stability.c_str(), ToString(p.stability_method), p.max_multiplier);
  std::string row = text;
  if (validated) std::snprintf(text, sizeof text, " %-10.1e", r.validation_error), row += text;
  if (has_reference) std::snprintf(text, sizeof text, " %.1e", r.reference_error()), row += text;
  return row + Marks(c, p) + (r.physical() ? "" : "  <- NON-PHYSICAL") + "\n";
}

std::string Table(const ContinuationSummary& c, const std::vector<BranchPointReport>& reports, bool validated,
                  bool has_reference) {
  std::string out = Header(c, validated, has_reference);
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
  if (b.type == BifurcationType::kNeimarkSacker) out["torus_frequency"] = JsonNumber(b.torus_frequency);
  return out;
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
    point["multipliers"] = JsonComplex(p.multipliers);
    point["trivial_multiplier"] = p.trivial_multiplier;
  }
  if (p.bifurcation >= 0) point["bifurcation"] = ToString(c.bifurcations[p.bifurcation].type);
  if (validated) point["validation_error"] = JsonNumber(r.validation_error);
  if (has_reference)
    point["reference"] = {{"frequency_error", JsonNumber(r.frequency_error)},
                          {"amplitude_error", JsonNumber(r.amplitude_error)}};
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
  return "";
}

bool BranchSummary::switch_failed() const {
  for (const DoubledBranchReport& d : doubled)
    if (!d.branch.started) return true;
  for (const TorusReport& t : tori)
    if (!t.start.solved) return true;
  return false;
}

BranchSummary ContinueModel(const Model& model, const HarmonicSolution& guess, const ContinueOptions& o) {
  if (const std::string error = o.IsValid(); !error.empty()) throw std::invalid_argument(error);
  // Both ends must be values the model accepts (bad input, not a failed step).
  const Model start = WithParameters(model, {{o.parameter, o.from}});
  try {
    WithParameters(model, {{o.parameter, o.to}});
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("at the end of the range: ") + e.what());
  }
  const ContinuationProblem problem = ModelContinuationProblem(
      [&model, name = o.parameter](double value) { return WithParameters(model, {{name, value}}); }, o.parameter,
      o.from, o.to);
  const ContinuationOptions options = TraceOptions(o);
  // The first point from the automatic start, so that a model file without
  // a guess can be traced.
  const StartedSolve started = SolveFromAnyStart(start, guess, o.harmonic_balance);
  BranchSummary b;
  b.start_route = started.route;
  b.continuation = TraceBranch(problem, started.summary.usable() ? *started.summary.solution : guess, options);
  b.has_reference = start.reference.has_frequency() || start.reference.has_amplitude();
  b.validated = o.validate;
  b.bases = static_cast<int>(start.problem.frequencies.size());
  for (size_t i = 0; i < b.continuation.points.size(); ++i) {
    b.reports.push_back(ReportPoint(model, o, b.continuation, b.continuation.points[i]));
    if (!b.reports.back().physical()) b.non_physical.push_back(i);
  }
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

std::string BranchSummary::BriefReport() const { return continuation.BriefReport(); }

std::string BranchSummary::FullReport(bool table) const {
  std::string out = BriefReport() + "\n";
  if (start_route != "guess" && !start_route.empty()) out += "first point from the " + start_route + " start\n";
  if (!continuation.message.empty()) out += continuation.message + "\n";
  out += StabilityLines(continuation, true);
  if (table) out += Table(continuation, reports, validated, has_reference);
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

#include "rmhb/pipeline/branch.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "rmhb/pipeline/report.h"

namespace rmhb {
namespace {

using nlohmann::json;

BranchPointReport ReportPoint(const Model& model, const ContinueOptions& o, const ContinuationSummary& branch,
                              const ContinuationPoint& p) {
  BranchPointReport r;
  r.peak = PeakValue(p.solution);
  r.stability = ToString(p.stability);
  const Model here = WithParameters(model, {{o.parameter, p.parameter}});
  if (here.problem.definitions) r.definitions = CheckDefinitions(p.solution, here.problem.definitions, branch.samples);
  const ReferenceErrors errors = ErrorsAgainst(here.reference, p.solution);
  r.frequency_error = errors.frequency;
  r.amplitude_error = errors.amplitude;
  if (o.validate) {
    const auto& w = p.solution.frequencies();
    const double period = 2 * M_PI / *std::min_element(w.begin(), w.end());
    const integrators::ValidationReport v = ValidateOriginal(here, p.solution, o.validate_periods * period, 401);
    r.validation_error = v.ok ? v.max_error : NAN;
  }
  return r;
}

ContinuationOptions TraceOptions(const ContinueOptions& o) {
  ContinuationOptions options;
  options.method = o.natural ? ContinuationMethod::kNatural : ContinuationMethod::kPseudoArclength;
  options.harmonic_balance = o.harmonic_balance;
  options.stability = o.stability;
  const double range = std::abs(o.to - o.from);
  options.initial_step = range / o.steps;
  options.max_step = o.max_step > 0 ? o.max_step : std::max(options.initial_step, range / 10);
  options.initial_step = std::min(options.initial_step, options.max_step);
  return options;
}

std::string Row(const BranchSummary& b, size_t i) {
  const ContinuationPoint& p = b.continuation.points[i];
  const BranchPointReport& r = b.reports[i];
  std::string w;
  char text[256];
  for (double v : p.solution.frequencies()) {
    std::snprintf(text, sizeof text, "%s%.15g", w.empty() ? "" : ",", v);
    w += text;
  }
  std::snprintf(text, sizeof text, "%-22.15g %-20s %-20.15g %-9.1e %-9s", p.parameter, w.c_str(), r.peak, p.residual,
                r.stability.c_str());
  std::string row = text;
  if (b.validated) std::snprintf(text, sizeof text, " %-10.1e", r.validation_error), row += text;
  if (b.has_reference) std::snprintf(text, sizeof text, " %.1e", r.reference_error()), row += text;
  return row + (p.fold ? "  <- fold" : "") + (r.physical() ? "" : "  <- NON-PHYSICAL") + "\n";
}

json PointJson(const BranchSummary& b, size_t i) {
  const ContinuationPoint& p = b.continuation.points[i];
  const BranchPointReport& r = b.reports[i];
  json w = json::array();
  for (double v : p.solution.frequencies()) w.push_back(JsonNumber(v));
  json point = {{"parameter", JsonNumber(p.parameter)}, {"frequencies", w},
                {"amplitude", JsonNumber(r.peak)},      {"residual", JsonNumber(p.residual)},
                {"iterations", p.iterations},          {"arclength", JsonNumber(p.arclength)},
                {"fold", p.fold},                      {"stability", r.stability}};
  if (b.validated) point["validation_error"] = JsonNumber(r.validation_error);
  if (b.has_reference)
    point["reference"] = {{"frequency_error", JsonNumber(r.frequency_error)},
                          {"amplitude_error", JsonNumber(r.amplitude_error)}};
  if (const auto& c = r.definitions) {
    point["physical"] = c->physical;
    point["definition_error"] = JsonNumber(c->error);
    point["definition_worst"] = c->worst_variable;
  }
  return point;
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
  return "";
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
  ContinuationProblem problem;
  problem.parameter = o.parameter;
  problem.start = o.from;
  problem.end = o.to;
  problem.build = [&](double value) { return WithParameters(model, {{o.parameter, value}}).problem; };
  BranchSummary b;
  b.continuation = TraceBranch(problem, guess, TraceOptions(o));
  b.has_reference = start.reference.has_frequency() || start.reference.has_amplitude();
  b.validated = o.validate;
  b.bases = static_cast<int>(start.problem.frequencies.size());
  for (size_t i = 0; i < b.continuation.points.size(); ++i) {
    b.reports.push_back(ReportPoint(model, o, b.continuation, b.continuation.points[i]));
    if (!b.reports.back().physical()) b.non_physical.push_back(i);
  }
  const ContinuationStatus status = b.continuation.status;
  b.message = b.continuation.message;
  b.status = !(b.continuation.completed() || status == ContinuationStatus::kLeftRange) ? BranchStatus::kStopped
             : b.non_physical.empty()                                                   ? BranchStatus::kCompleted
                                                                                        : BranchStatus::kNonPhysical;
  return b;
}

std::string BranchSummary::BriefReport() const { return continuation.BriefReport(); }

std::string BranchSummary::FullReport(bool table) const {
  std::string out = BriefReport() + "\n";
  if (!continuation.message.empty()) out += continuation.message + "\n";
  if (!continuation.stability_note.empty()) out += "stability unknown: " + continuation.stability_note + "\n";
  if (!table) return out;
  char header[256];
  std::snprintf(header, sizeof header, "\n%-22s %-20s %-20s %-9s %-9s%s%s\n", continuation.parameter.c_str(),
                "frequency", "amplitude max|x|", "residual", "stability", validated ? " validation" : "",
                has_reference ? " exact error" : "");
  out += header;
  for (size_t i = 0; i < continuation.points.size(); ++i) out += Row(*this, i);
  return out;
}

json BranchSummary::ToJson() const {
  const ContinuationSummary& c = continuation;
  json branch = json::array(), folds = json::array();
  for (size_t i = 0; i < c.points.size(); ++i) {
    branch.push_back(PointJson(*this, i));
    if (c.points[i].fold) folds.push_back(JsonNumber(c.points[i].parameter));
  }
  return {{"parameter", c.parameter},
          {"range", {JsonNumber(c.start), JsonNumber(c.end)}},
          {"method", ToString(c.method)},
          {"status", ToString(c.status)},
          {"message", c.message},
          {"stability_note", c.stability_note},
          {"order", c.order},
          {"samples", c.samples.size() == 1 ? json(c.samples[0]) : json(c.samples)},
          {"points", c.points.size()},
          {"folds", folds},
          {"accepted_steps", c.accepted_steps},
          {"rejected_steps", c.rejected_steps},
          {"arclength", JsonNumber(c.arclength)},
          {"seconds", c.seconds},
          {"branch", branch}};
}

}  // namespace rmhb

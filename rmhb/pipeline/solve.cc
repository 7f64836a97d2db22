#include "rmhb/pipeline/solve.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "rmhb/pipeline/report.h"

namespace rmhb {
namespace {

using nlohmann::json;

// printf into a std::string.
template <typename... Args>
std::string Format(const char* format, Args... args) {
  char text[1024];
  std::snprintf(text, sizeof text, format, args...);
  return text;
}

double SlowestPeriod(const HarmonicSolution& s) {
  return 2 * M_PI / *std::min_element(s.frequencies().begin(), s.frequencies().end());
}

SolveValidation Validate(const Model& model, const HarmonicSolution& sol, const SolveOptions& o) {
  SolveValidation v;
  v.periods = o.validate_periods;
  v.t_end = o.validate_periods * SlowestPeriod(sol);
  v.report = ValidateOriginal(model, sol, v.t_end);
  v.verdict = JudgeValidation(model, sol, v.report, v.t_end, o.validate_tolerance);
  return v;
}

json SamplesJson(const std::vector<int>& samples) { return samples.size() == 1 ? json(samples[0]) : json(samples); }

// The lines between the brief line and the requested ones.
std::string Details(const SolveSummary& s) {
  const HarmonicBalanceSummary& hb = s.harmonic_balance;
  std::string out = "\n" + s.model_name + ": " + s.equation + "\n";
  if (s.equations == "original")
    out += "original equations (" + (s.equations_note.empty() ? std::string("--equations original") : s.equations_note) +
           "):\n" + s.recast;
  else
    out += Format("recast (phi = %d):\n", hb.degree) + s.recast;
  if (!s.frequency_note.empty()) out += "frequencies  " + s.frequency_note + "\n";
  if (!s.default_conditions.empty())
    out += "conditions   " + DefaultConditionsText(s.default_conditions, s.conditions_note) + "\n";
  for (const std::string& symmetry : s.symmetries) out += "symmetry     " + symmetry + " (the guess has it)\n";
  for (const HalfTurnSymmetry& symmetry : hb.symmetries_found)
    out += "symmetry     " + symmetry.description + " (found: the recorded start or the first solution has it)\n";
  out += "status       " + s.status_word() + (hb.solver.message.empty() ? "" : ": ") + hb.solver.message + "\n";
  out += Format("residual     %.3e after %d iterations (%s)\n", hb.solver.final_residual, hb.solver.iterations,
                ToString(hb.solver.method));
  out += Format("time         %.3f ms\n", hb.seconds * 1e3);
  out += Format("linear       %s, %d unknowns", ToString(hb.solver.linear_solver), hb.solver.num_unknowns);
  if (hb.solver.linear_solver == LinearSolver::kKrylov)
    out += Format(", %d GMRES iterations", hb.solver.linear_iterations);
  out += Format("; peak memory %.0f MiB\n", s.peak_memory_bytes / (1 << 20));
  if (s.start_route != "guess" || !s.start_note.empty())
    out += "start        " + s.start_route + (s.start_note.empty() ? "" : "; ") + s.start_note + "\n";
  if (s.converged()) out += "physical     " + PhysicalLine(hb) + "\n";
  if (hb.truncation_estimate >= 0) {
    out += Format("order        %d %s target %g on the %s (orders", hb.order,
                  s.converged() && hb.truncation_estimate <= hb.tolerance ? "chosen for" : "reached, short of",
                  hb.tolerance, ToString(hb.tolerance_quantity));
    for (int o : hb.orders_tried) out += Format(" %d", o);
    out += Format("), estimated error: state %.1e", hb.state_estimate);
    if (hb.frequency_estimate >= 0) out += Format(", frequency %.1e", hb.frequency_estimate);
    out += hb.estimate_calibrated ? " (calibrated on a lower order" : " (coefficient tail";
    if (hb.sampling_estimate >= 0)
      out += Format("; sampling %.1e of it, from a solve on half the samples", hb.sampling_estimate);
    out += ")\n";
  }
  if (hb.solver.reciprocal_condition > 0) {
    out += Format("condition    1/cond(J) ~ %.2e (last factorised Jacobian)", hb.solver.reciprocal_condition);
    if (hb.solver.scaling == Scaling::kEquilibrate)
      out += Format(", equilibrated D_r J D_c ~ %.2e", hb.solver.scaled_reciprocal_condition);
    out += "\n";
  }
  if (!s.converged()) return out;
  const HarmonicSolution& sol = s.solution();
  for (double w : sol.frequencies()) out += Format("frequency    %.17g  (period %.17g)\n", w, 2 * M_PI / w);
  if (s.bases > 1) out += Format("harmonics    %d index vectors (%s)\n", sol.basis().size(), sol.basis().shape().c_str());
  for (int j = 0; j < sol.num_variables(); ++j) {
    if (sol.variables()[j].role == VariableRole::kAuxiliary) continue;
    out += Format("%-12s", sol.variables()[j].name.c_str());
    const int shown = std::min(sol.basis().size(), 6);
    for (int k = 0; k < shown; ++k)
      out += Format(" k=%d:(%.6g, %.6g)", k, k ? sol.coefficients()(j, 2 * k - 1) : sol.coefficients()(j, 0),
                    k ? sol.coefficients()(j, 2 * k) : 0.0);
    out += sol.basis().size() > shown ? " ...\n" : "\n";
  }
  if (!s.errors) return out;
  if (s.reference.has_frequency())
    out += Format("error        frequency %.3e (against %s)\n", s.errors->frequency, s.reference.source.c_str());
  if (s.reference.has_amplitude()) out += Format("error        amplitude %.3e\n", s.errors->amplitude);
  if (s.reference.solution) out += Format("error        max over one period %.3e\n", s.errors->max_error);
  return out;
}

}  // namespace

const char* ToString(SolveStatus status) {
  switch (status) {
    case SolveStatus::kConverged: return "converged";
    case SolveStatus::kNotConverged: return "not_converged";
    case SolveStatus::kNonPhysical: return "non_physical";
    case SolveStatus::kValidationExceeded: return "validation_exceeded";
  }
  return "unknown";
}

std::string SolveOptions::IsValid() const {
  if (validate_periods < 1) return "validate_periods must be >= 1 (got " + std::to_string(validate_periods) + ")";
  if (!(validate_tolerance > 0) || !std::isfinite(validate_tolerance))
    return "validate_tolerance must be finite and > 0";
  return start.IsValid();
}

std::string SolveSummary::status_word() const {
  const HarmonicBalanceSummary& hb = harmonic_balance;
  return !hb.converged() ? ToString(hb.solver.status) : hb.physical ? "converged" : "non_physical";
}

std::string SolveSummary::BriefReport() const { return harmonic_balance.BriefReport(); }

std::string SolveSummary::FullReport() const { return BriefReport() + "\n" + Details(*this) + RequestedReport(); }

std::string SolveSummary::RequestedReport() const {
  std::string out = stability ? stability->FullReport() : "";
  if (!validation) return out;
  const integrators::ValidationReport& v = validation->report;
  if (!std::isfinite(v.max_error))
    return out + Format("validation   failed: %s integration did not finish: %s (%.1f ms)\n", v.integrator.c_str(),
                        v.message.c_str(), v.seconds * 1e3);
  const bool ok = std::string(validation->status()) == "ok";
  return out + Format("validation   %s: max error %.3e (relative %.2e %s tolerance %.0e) over %d (longest) period(s) "
                      "against %s (%.1f ms)\n",
                      ok ? "ok" : "EXCEEDS", v.max_error, validation->verdict.relative_error, ok ? "<=" : ">",
                      validation->verdict.tolerance, validation->periods, v.integrator.c_str(), v.seconds * 1e3);
}

json SolveSummary::ToJson() const {
  const HarmonicBalanceSummary& hb = harmonic_balance;
  json out;
  out["status"] = status_word();
  out["message"] = hb.solver.message;
  out["start"] = start_route;
  if (!start_note.empty()) out["start_note"] = start_note;
  out["equations"] = equations;
  if (!equations_note.empty()) out["equations_note"] = equations_note;
  if (!frequency_note.empty()) out["frequency_note"] = frequency_note;
  if (!default_conditions.empty()) out["default_conditions"] = DefaultConditionsJson(default_conditions, conditions_note);
  if (!symmetries.empty() || !hb.symmetries_found.empty()) {
    std::vector<std::string> all = symmetries;
    for (const HalfTurnSymmetry& symmetry : hb.symmetries_found) all.push_back(symmetry.description);
    out["symmetries"] = all;
  }
  out["method"] = ToString(options.rule);
  out["solver"] = ToString(hb.solver.method);
  out["order"] = hb.order;
  if (hb.truncation_estimate >= 0)
    out["order_selection"] = {{"tolerance", hb.tolerance},
                              {"quantity", ToString(hb.tolerance_quantity)},
                              {"orders", hb.orders_tried},
                              {"estimate", JsonNumber(hb.truncation_estimate)},
                              {"state_estimate", JsonNumber(hb.state_estimate)},
                              {"frequency_estimate", hb.frequency_estimate >= 0 ? JsonNumber(hb.frequency_estimate)
                                                                                : json(nullptr)},
                              {"calibrated", hb.estimate_calibrated},
                              {"sampling_estimate",
                               hb.sampling_estimate >= 0 ? JsonNumber(hb.sampling_estimate) : json(nullptr)}};
  // null when not computed (the solve failed before a Jacobian was factorised).
  out["reciprocal_condition"] =
      hb.solver.reciprocal_condition > 0 ? JsonNumber(hb.solver.reciprocal_condition) : json(nullptr);
  out["scaled_reciprocal_condition"] =
      hb.solver.scaled_reciprocal_condition > 0 ? JsonNumber(hb.solver.scaled_reciprocal_condition) : json(nullptr);
  out["scaling"] = ToString(hb.solver.scaling);
  out["scaled_residual"] = JsonNumber(hb.solver.scaled_residual);
  out["samples"] = SamplesJson(hb.samples);
  out["alias_free_samples"] = SamplesJson(hb.alias_free_samples);
  out["sampling"] = hb.sampling;
  out["alias_free"] = hb.alias_free;
  out["degree"] = hb.degree;
  out["iterations"] = hb.solver.iterations;
  out["linear_solver"] = ToString(hb.solver.linear_solver);
  out["linear_iterations"] = hb.solver.linear_iterations;
  out["unknowns"] = hb.solver.num_unknowns;
  out["peak_memory_bytes"] = peak_memory_bytes;
  out["residual"] = JsonNumber(hb.solver.final_residual);
  out["seconds"] = hb.seconds;
  out.update(PhysicalJson(hb));
  if (converged()) {
    out.update(SolutionJson(solution()));
  } else {
    json freqs = json::array();
    if (hb.solution)
      for (double w : hb.solution->frequencies()) freqs.push_back(JsonNumber(w));
    out["frequencies"] = freqs;
  }
  if (errors && (reference.has_frequency() || reference.has_amplitude() || reference.solution)) {
    json r = {{"source", reference.source}};
    if (reference.has_frequency()) r["frequency_error"] = JsonNumber(errors->frequency);
    if (reference.has_amplitude()) r["amplitude_error"] = JsonNumber(errors->amplitude);
    if (reference.solution) r["max_error"] = JsonNumber(errors->max_error);
    out["reference"] = r;
  }
  if (validation) {
    const integrators::ValidationReport& v = validation->report;
    out["validation"] = {{"status", validation->status()},
                         {"max_error", JsonNumber(v.max_error)},
                         {"relative_error", JsonNumber(validation->verdict.relative_error)},
                         {"tolerance", validation->verdict.tolerance},
                         {"periods", validation->periods},
                         {"t_end", validation->t_end},
                         {"seconds", v.seconds},
                         {"integrator", v.integrator},
                         {"message", v.message}};
  }
  if (stability) out["stability"] = stability->ToJson();
  return out;
}

namespace {

// What a start reached, for a note: its route and why it was not kept.
std::string StartText(const StartedSolve& started) {
  return "from the " + started.route + ", " + WhyNotKept(started.summary) +
         (started.note.empty() ? "" : " (" + started.note + ")");
}

// The model on its original equations, solved from every start at the same
// order and target; nullopt when that reaches no physical solution either.
std::optional<SolveSummary> SolveOnOriginalEquations(const Model& given, const SolveOptions& options) {
  const Model original = OriginalEquationsOf(given);
  SolveSummary s = SolveModel(original, GuessAtOrder(original, options.harmonic_balance.order), options);
  if (!s.harmonic_balance.usable()) return std::nullopt;
  return s;
}

}  // namespace

SolveSummary SolveModel(const Model& given, const HarmonicSolution& guess, const SolveOptions& options) {
  if (const std::string error = options.IsValid(); !error.empty()) throw std::invalid_argument(error);
  // The equations' symmetries that the guess has: half the unknowns, the
  // same answer (ImposeGuessSymmetries). A copy only when there are any.
  std::optional<Model> symmetric;
  if (!given.invariances.empty()) {
    symmetric = given;
    if (ImposeGuessSymmetries(guess, &*symmetric) == 0) symmetric.reset();
  }
  const Model& model = symmetric ? *symmetric : given;
  if (options.validate && !model.original && !model.original_dae)
    throw std::invalid_argument("cannot validate: " + model.original_error);
  SolveSummary s;
  s.options = options.harmonic_balance;
  s.model_name = model.name;
  s.equation = model.equation;
  s.recast = model.problem.system.ToString();
  s.equations = model.equations;
  s.equations_note = model.equations_note;
  s.default_conditions = model.DefaultConditions();
  s.conditions_note = model.conditions_note;
  s.frequency_note = model.frequency_note;
  for (size_t i = given.problem.symmetries.size(); i < model.problem.symmetries.size(); ++i)
    s.symmetries.push_back(model.problem.symmetries[i].description);
  s.bases = static_cast<int>(model.problem.frequencies.size());
  s.reference = model.reference;
  StartedSolve started = options.auto_start
                             ? SolveFromAnyStart(model, guess, options.harmonic_balance, options.start)
                             : StartedSolve{SolveHarmonicBalance(model.problem, guess, options.harmonic_balance),
                                            "guess", "", 0};
  if (options.auto_start && !started.summary.usable() && given.original_equations) {
    // Last resort: the equations as written (HB-AFT, METHOD.md s.13), every
    // start again. Kept only when it reaches a physical solution.
    std::optional<SolveSummary> original = SolveOnOriginalEquations(given, options);
    if (original) {
      original->start_route += " on the original equations";
      original->start_note = "the recast reached no physical solution: " + StartText(started) +
                             (original->start_note.empty() ? "" : "; ") + original->start_note;
      return std::move(*original);
    }
    started.note += (started.note.empty() ? "" : "; ") + std::string("the original equations did not either");
  }
  s.harmonic_balance = std::move(started.summary);
  s.start_route = started.route;
  s.start_note = started.note;
  const HarmonicBalanceSummary& hb = s.harmonic_balance;
  if (!hb.converged()) {
    s.status = SolveStatus::kNotConverged;
    s.message = hb.solver.message;
    s.peak_memory_bytes = PeakMemoryBytes();
    return s;
  }
  if (!model.reference.empty()) s.errors = ErrorsAgainst(model.reference, s.solution());
  if (options.validate) s.validation = Validate(model, s.solution(), options);
  if (options.stability) s.stability = Stability(model, s.solution());
  s.peak_memory_bytes = PeakMemoryBytes();
  if (!hb.physical) {
    s.status = SolveStatus::kNonPhysical;
    s.message = hb.non_physical;
  } else if (s.validation && std::string(s.validation->status()) == "exceeds") {
    s.status = SolveStatus::kValidationExceeded;
    s.message = s.validation->verdict.Describe();
  } else {
    s.status = SolveStatus::kConverged;
  }
  return s;
}

SolveSummary SolveModel(const Model& model, const SolveOptions& options) {
  return SolveModel(model, GuessAtOrder(model, options.harmonic_balance.order), options);
}

}  // namespace rmhb

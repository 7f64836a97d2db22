#include "rmhb/pipeline/report.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>

namespace rmhb {

std::string StringPrintf(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int length = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string text(length > 0 ? length : 0, '\0');
  if (length > 0) std::vsnprintf(text.data(), text.size() + 1, format, again);
  va_end(again);
  return text;
}

namespace {

using nlohmann::json;

json Coefficients(const HarmonicSolution& s, int j) {
  const auto& c = s.coefficients();
  json cos = json::array(), sin = json::array();
  cos.push_back(JsonNumber(c(j, 0)));
  sin.push_back(0.0);
  for (int k = 1; k < s.basis().size(); ++k) {
    cos.push_back(JsonNumber(c(j, 2 * k - 1)));
    sin.push_back(JsonNumber(c(j, 2 * k)));
  }
  return {{"cos", cos}, {"sin", sin}};
}

}  // namespace

json JsonNumber(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json JsonComplex(const std::vector<std::complex<double>>& values) {
  json out = json::array();
  for (const auto& v : values) out.push_back({JsonNumber(v.real()), JsonNumber(v.imag())});
  return out;
}

json SolutionJson(const HarmonicSolution& sol) {
  const int bases = static_cast<int>(sol.frequencies().size());
  json out;
  json freqs = json::array();
  for (double w : sol.frequencies()) freqs.push_back(JsonNumber(w));
  out["frequencies"] = freqs;
  json coeffs = json::object(), aux = json::object();
  for (int j = 0; j < sol.num_variables(); ++j) {
    const auto& v = sol.variables()[j];
    (v.role == VariableRole::kAuxiliary ? aux : coeffs)[v.name] = Coefficients(sol, j);
  }
  out["coefficients"] = coeffs;
  json harmonics = json::array();
  for (const auto& k : sol.basis().harmonics()) harmonics.push_back(bases == 1 ? json(k[0]) : json(k));
  out["harmonics"] = harmonics;
  out["auxiliary_coefficients"] = aux;
  return out;
}

json DefaultConditionsJson(const std::vector<std::string>& conditions, const std::string& note) {
  return {{"conditions", conditions}, {"note", note}};
}

std::string DefaultConditionsText(const std::vector<std::string>& conditions, const std::string& note) {
  std::string out;
  for (const std::string& c : conditions) out += (out.empty() ? "" : " ") + c;
  return out + "; " + note;
}

json PhysicalJson(const HarmonicBalanceSummary& summary) {
  json out = json::object();
  if (!summary.converged()) return out;
  out["physical"] = summary.physical;
  if (!summary.physical) out["non_physical"] = summary.non_physical;
  if (summary.alias_residual >= 0) {
    out["alias_residual"] = JsonNumber(summary.alias_residual);
    out["alias_check_samples"] = summary.alias_check_samples;
    out["alias_tolerance"] = summary.alias_tolerance;
  }
  if (const auto& c = summary.definition_check) {
    out["definition_error"] = JsonNumber(c->error);
    out["definition_worst"] = c->worst_variable;
    out["definition_worst_time"] = JsonNumber(c->worst_time);
    out["definition_tolerance"] = JsonNumber(c->tolerance);
    out["definition_points"] = c->points;
    out["definition_seconds"] = c->seconds;
  }
  return out;
}

std::string PhysicalLine(const HarmonicBalanceSummary& summary) {
  if (!summary.converged()) return "";
  if (!summary.physical) return "NO: " + summary.non_physical;
  if (summary.alias_residual >= 0) {
    char text[160];
    long points = 1;
    for (int m : summary.alias_check_samples) points *= m;
    std::snprintf(text, sizeof text, "yes: residual on %ld samples (twice the solve's) %.2e (relative) <= %.0e",
                  points, summary.alias_residual, summary.alias_tolerance);
    return text;
  }
  if (summary.definition_check) return "yes: " + summary.definition_check->Report();
  return "yes (no collapsed frequency; no auxiliaries to check)";
}

json RecastJson(const Model& model) {
  const PolynomialSystem& sys = model.problem.system;
  json vars = json::array(), eqs = json::array(), conds = json::array();
  for (const auto& v : sys.variables())
    vars.push_back({{"name", v.name},
                    {"role", v.role == VariableRole::kAuxiliary ? "auxiliary" : "state"},
                    {"definition", v.definition}});
  for (const auto& e : sys.equations())
    eqs.push_back({{"equation", e.lhs.ToString(sys.names()) + " = 0"}, {"balance_constant", e.balance_constant}});
  for (const auto& c : model.problem.conditions) conds.push_back(c.description);
  json w = json::array();
  for (size_t b = 0; b < model.problem.frequencies.size(); ++b)
    w.push_back({{"value", model.problem.frequencies[b]},
                 {"unknown", !model.problem.unknown_frequency.empty() && model.problem.unknown_frequency[b]}});
  return {{"equation", model.equation}, {"degree", sys.Degree()}, {"variables", vars},
          {"equations", eqs},           {"conditions", conds},    {"frequencies", w}};
}

std::string RecastReport(const Model& model) {
  const PolynomialSystem& sys = model.problem.system;
  std::string out = model.name + ": " + model.equation + "\n\n" + model.recast_report;
  if (!model.from_file && !model.problem.conditions.empty()) {
    out += "conditions at t = 0:\n";
    for (const auto& c : model.problem.conditions) out += "  " + c.description + "\n";
  }
  char line[128];
  std::snprintf(line, sizeof line, "degree phi = %d: RHB with N harmonics needs M > %d N samples\n", sys.Degree(),
                sys.Degree() + 1);
  return out + line;
}

}  // namespace rmhb

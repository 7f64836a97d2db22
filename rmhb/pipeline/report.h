#ifndef RMHB_PIPELINE_REPORT_H_
#define RMHB_PIPELINE_REPORT_H_

// The pieces every study's report shares, as JSON (nlohmann::json) and
// text: a number (JSON has no NaN or inf: a non-finite number must never be
// printed as a result, so it becomes null), a solution's coefficients, the
// physical check of a converged solve, a model's recast. The studies'
// summaries (SolveSummary, BranchSummary, ...) build their ToJson() from
// these, so a field means the same in every command's --json.

#include <complex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/model.h"

namespace rmhb {

// v, or null when not finite.
// printf into a string as long as the text needs (the reports' lines).
std::string StringPrintf(const char* format, ...) __attribute__((format(printf, 1, 2)));

nlohmann::json JsonNumber(double v);
// [[re, im], ...], non-finite parts null.
nlohmann::json JsonComplex(const std::vector<std::complex<double>>& values);

// The solution as the documented fields: frequencies, harmonics (index
// vectors; plain integers for one base), coefficients of the original
// variables and auxiliary_coefficients ({"cos": [...], "sin": [...]} each).
nlohmann::json SolutionJson(const HarmonicSolution& solution);

// The physical check of a converged solve (HarmonicBalanceSummary::physical):
// "physical", "non_physical" (why, when not), and with a definition check
// "definition_error", "definition_worst", "definition_worst_time",
// "definition_tolerance", "definition_points", "definition_seconds". Empty
// when the solve did not converge.
nlohmann::json PhysicalJson(const HarmonicBalanceSummary& summary);
// The verdict in words: "yes: max |solved - definition| ..." or "NO: why";
// empty when the solve did not converge.
std::string PhysicalLine(const HarmonicBalanceSummary& summary);

// The conditions a model file got by default (Model::DefaultConditions) and
// why: {"conditions": [...], "note": ...} for --json, and "c1 c2; note" for
// a report line after its label.
nlohmann::json DefaultConditionsJson(const std::vector<std::string>& conditions, const std::string& note);
std::string DefaultConditionsText(const std::vector<std::string>& conditions, const std::string& note);

// The recast of a model: equation, degree, variables (name, role,
// definition), equations (with balance_constant), conditions, frequencies
// (value, unknown).
nlohmann::json RecastJson(const Model& model);
// The same as text: "name: equation", the polynomial system, the conditions
// (built-in examples; a model file's recast report lists its own) and the
// degree with the alias-free bound.
std::string RecastReport(const Model& model);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_REPORT_H_

#ifndef RMHB_MODEL_INTERNAL_SYMBOLIC_TOOLS_H_
#define RMHB_MODEL_INTERNAL_SYMBOLIC_TOOLS_H_

// Helpers shared by the recast and the original system: parameter
// substitution and the recognition of harmonic time functions.

#include <string>
#include <vector>

#include <ginac/ginac.h>

#include "rmhb/model/model_definition.h"
#include "rmhb/model/internal/symbolic_model.h"

namespace rmhb::model::internal {

struct Bases {
  std::vector<GiNaC::symbol> symbols;
  std::vector<double> values;  // known values, or guesses of unknown ones
  std::vector<bool> unknown;
  GiNaC::exmap KnownValues() const;  // symbol -> exact value, known bases only
  GiNaC::exmap AllValues() const;    // every base
};

// parameter symbol -> exact rational value, for every parameter that is not
// also a base frequency symbol.
GiNaC::exmap ParameterSubstitution(const SymbolicModel& symbolic, const ParameterValues& values);

// Evaluates the base frequencies of the model with these parameter values.
// Throws ModelError (located at the frequency entry) if one is not > 0.
Bases EvaluateBases(const ModelDefinition& model, const ParameterValues& values);

// Whether arg = k.w t + phase with integer k: k from the base symbols, or
// numerically from the known base values. phase must not contain t.
// `numeric` (optional) is set when the answer came from the base values
// (then it depends on them), left alone otherwise.
bool AnalyzeHarmonic(const GiNaC::ex& arg, const GiNaC::symbol& t, const Bases& bases,
                     std::vector<int>* k, GiNaC::ex* phase, bool* numeric = nullptr);

// A deterministic, readable form of e: operands of sums and products sorted
// by their own printed form (GiNaC orders them by hash values, which depend
// on the order symbols were created in the process), quotients and square
// roots written as such: "1/(1 + x^2)", "sqrt(1 - x'^2)", "x*y - 2*z".
// The recast also uses it to visit operands in a reproducible order, so the
// numbering of auxiliaries does not depend on what ran before.
std::string Print(const GiNaC::ex& e);

// Rewrites an expression of t as a function of the torus angles:
// cos(k.w t + phase) -> cos(k.theta + phase); with one base any remaining t
// becomes theta_1 / w_1. Base symbols are replaced by their values. Throws
// std::invalid_argument when t is left with several bases or a time
// function is not harmonic.
GiNaC::ex ToAngles(const GiNaC::ex& e, const GiNaC::symbol& t, const Bases& bases,
                   const std::vector<GiNaC::symbol>& angles);

}  // namespace rmhb::model::internal

#endif  // RMHB_MODEL_INTERNAL_SYMBOLIC_TOOLS_H_

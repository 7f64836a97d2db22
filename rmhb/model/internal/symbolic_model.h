#ifndef RMHB_MODEL_INTERNAL_SYMBOLIC_MODEL_H_
#define RMHB_MODEL_INTERNAL_SYMBOLIC_MODEL_H_

// The parsed expressions of a ModelDefinition (GiNaC), shared by the recast
// and the original-system builder. Parameters stay symbols here: their values
// (with overrides) are substituted by Recast as exact rationals.

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <ginac/ginac.h>

namespace rmhb::model::internal {

struct SymbolicModel {
  GiNaC::symbol t{"t"};
  // One symbol per base frequency; a parameter's symbol when the frequency
  // entry names a parameter.
  std::vector<GiNaC::symbol> bases;
  std::map<std::string, GiNaC::symbol> parameters;
  // derivatives[v][j]: the j-th derivative of variable v, printed x, x', x''.
  std::vector<std::vector<GiNaC::symbol>> derivatives;

  std::vector<GiNaC::ex> equations;         // lhs - rhs
  std::vector<GiNaC::ex> conditions;        // lhs - rhs, derivative symbols = values at t = 0
  std::vector<GiNaC::ex> frequency_values;  // of the parameters
  // ((variable, derivative order), value expression of the parameters).
  std::vector<std::pair<std::pair<int, int>, GiNaC::ex>> initial_state;
  std::vector<GiNaC::ex> guess;  // per variable, of t, parameters, bases
  std::vector<bool> has_guess;
};

}  // namespace rmhb::model::internal

#endif  // RMHB_MODEL_INTERNAL_SYMBOLIC_MODEL_H_

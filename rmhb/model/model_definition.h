#ifndef RMHB_MODEL_MODEL_DEFINITION_H_
#define RMHB_MODEL_MODEL_DEFINITION_H_

// A model as the user writes it: a YAML file with the equations in natural
// notation (FORMAT.md beside this header describes the format).
//
//   ModelDefinition m = LoadModelFile("examples/models/pendulum.yaml");
//   RecastResult r = Recast(m, {{"theta0", 1.2}});   // recast.h
//
// Loading checks everything that can be checked without parameter values:
// YAML syntax, the schema, every expression (unknown symbols, unsupported
// functions, malformed syntax), the count of equations against variables,
// that each variable appears. Every problem is a ModelError with the file,
// line and column. The parsed expressions are kept in `symbolic` (GiNaC,
// hidden from this header); the rest are plain values for reports and tools.
//
// GiNaC is not thread-safe: load, recast and build guesses from one thread at
// a time (the compiled evaluators the recast returns are thread-compatible).

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "rmhb/model/model_error.h"

namespace rmhb::model {

namespace internal {
struct SymbolicModel;
}

// Parameter overrides, e.g. from a command line "--set eps=2".
using ParameterValues = std::map<std::string, double>;

// A string of the file (an equation, a condition, an expression) and where
// its first character is.
struct SourceText {
  std::string text;
  SourceLocation where;
};

struct ParameterDefinition {
  std::string name;
  double value = 0;
  SourceLocation where;
};

struct FrequencyDefinition {
  // Name of the base in the equations: "w" (one base) or "w1", "w2", ...; or
  // the parameter the entry names (`frequencies: [w]` with a parameter w).
  std::string symbol;
  bool unknown = false;    // {guess: value}: solved for
  SourceText value;        // the number or expression (of parameters) given
  std::string parameter;   // non-empty when bound to a parameter
};

struct ModelDefinition {
  std::string name;
  std::string description;
  std::string source;  // file name used in error messages
  std::string text;    // the model text as parsed (to parse again with conditions added)

  std::vector<std::string> variables;
  // Highest derivative order of each variable in the equations (x'' -> 2).
  std::vector<int> orders;
  std::vector<ParameterDefinition> parameters;
  std::vector<SourceText> equations;
  std::vector<FrequencyDefinition> frequencies;
  std::vector<SourceText> conditions;
  // Keys "x", "x'", ... (each below the variable's order); values are
  // expressions of the parameters.
  std::vector<std::pair<std::string, SourceText>> initial_state;
  // Variable name -> expression of t, the parameters and the bases.
  std::vector<std::pair<std::string, SourceText>> guess;

  // An autonomous file without 'frequencies' but with initial_state: its one
  // unknown base has the placeholder guess 1 until the loader reads the
  // guess off the trajectory (rmhb/pipeline/model.h) and parses again.
  bool frequency_from_trajectory = false;
  std::string frequency_guess;  // the guess it was parsed with then (ParseModel)

  std::shared_ptr<const internal::SymbolicModel> symbolic;

  int num_bases() const { return static_cast<int>(frequencies.size()); }
  int IndexOfVariable(const std::string& name) const;  // -1 if absent
  const ParameterDefinition* FindParameter(const std::string& name) const;
  // The parameter values with `overrides` applied. Throws ModelError for an
  // override naming no parameter or a non-finite value.
  ParameterValues ParameterValuesWith(const ParameterValues& overrides) const;
};

// Parses model text; `source_name` is used in error messages (a file name).
// `added_conditions` (texts like "x'(0) = 0") follow the file's own: the
// conditions a model without any gets by default (rmhb/pipeline/model.h).
// `frequency_guess` (a number's text) is the guess of an autonomous model
// that gives no 'frequencies' (its default, rmhb/pipeline/model.h).
ModelDefinition ParseModel(const std::string& text, const std::string& source_name,
                           const std::vector<std::string>& added_conditions = {},
                           const std::string& frequency_guess = "");
// Reads and parses a file; errors name `path` as given.
ModelDefinition LoadModelFile(const std::string& path);

}  // namespace rmhb::model

#endif  // RMHB_MODEL_MODEL_DEFINITION_H_

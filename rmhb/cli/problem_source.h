#ifndef RMHB_CLI_PROBLEM_SOURCE_H_
#define RMHB_CLI_PROBLEM_SOURCE_H_

// What the CLI works on, whatever it came from: a bundled example (hand-
// written recast, exact references) or a model file (automatic recast). The
// commands see one description: the harmonic balance problem, a starting
// guess, the original equations for validation, and any exact reference.

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "examples/example_system.h"
#include "rmhb/pipeline/model.h"

namespace rmhb::cli {

// A model (rmhb/pipeline/model.h): from a file, or a built-in example with
// its exact reference.
using ProblemSource = Model;

// A path (contains '/' or ends in .yaml/.yml, or names an existing file) is
// a model file; anything else an example name. Throws std::invalid_argument
// (unknown example/parameter) or model::ModelError (file:line:column).
ProblemSource LoadProblem(const std::string& model, const std::map<std::string, double>& overrides);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_PROBLEM_SOURCE_H_

#ifndef RMHB_EXAMPLES_EXAMPLE_SYSTEM_H_
#define RMHB_EXAMPLES_EXAMPLE_SYSTEM_H_

// The paper's test systems, each with its original ODE (for validation by
// integration), its polynomial recast written by hand, a starting guess, and
// its exact reference where one exists. Tests, benchmarks, the CLI and the
// docs all use these, so that a number quoted anywhere refers to the same
// problem.

#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "rmhb/collocation_residual.h"
#include "rmhb/pipeline/reference.h"
#include "rmhb/harmonic_solution.h"

namespace rmhb::examples {

struct Parameter {
  std::string name;
  double value;
  std::string meaning;
  // >= 0: the parameter is base frequency `base` of the problem and enters
  // it nowhere else (a forcing frequency): Model::frequency_parameters.
  // Declared here (the recast is hand-written), checked by
  // tests/pipeline/parameter_rebuild_test.cc.
  int base = -1;
};

// y' = f(t, y) in the user's own variables, and how to read y(t) off a
// harmonic balance solution.
struct OriginalOde {
  std::vector<std::string> names;
  std::function<void(double t, const double* y, double* ydot)> rhs;
  std::function<Eigen::VectorXd(const HarmonicSolution&, double t)> state;
  bool stiff = false;  // integrate with BDF rather than Adams
  // The state the conditions fix at t = 0 (a conservative motion), or where
  // an attractor's simulation starts; empty when the example has none.
  Eigen::VectorXd initial_state;
  // Every harmonic balance variable from a state (the recast's auxiliaries
  // from their definitions); empty when the variables are the state itself.
  std::function<Eigen::VectorXd(const Eigen::VectorXd& y)> variables;
  int dimension() const { return static_cast<int>(names.size()); }
};

// The exact answers of an example (rmhb/pipeline/reference.h).
using Reference = ExactReference;

struct ExampleSetup {
  HarmonicBalanceProblem problem;
  HarmonicSolution guess;
  OriginalOde original;
  Reference reference;
  int default_order = 10;
};

struct Example {
  std::string name;
  std::string description;
  std::string equation;  // the original equation, as a user writes it
  std::vector<Parameter> parameters;
  std::function<ExampleSetup(const std::map<std::string, double>& values)> build;
};

const std::vector<Example>& AllExamples();
// nullptr when unknown.
const Example* FindExample(const std::string& name);
// Builds with defaults overridden by `overrides`. Throws std::invalid_argument
// naming an unknown example or parameter, or a non-finite / out-of-range value.
ExampleSetup BuildExample(const std::string& name,
                          const std::map<std::string, double>& overrides = {});

}  // namespace rmhb::examples

#endif  // RMHB_EXAMPLES_EXAMPLE_SYSTEM_H_

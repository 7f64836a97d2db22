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
#include "rmhb/seeding/identified_guess.h"
#include "integrators/ode_system.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/collocation_residual.h"
#include "rmhb/harmonic_solution.h"
#include "rmhb/model/model_definition.h"
#include "rmhb/model/original_system.h"

namespace rmhb::cli {

struct ProblemSource {
  std::string name;
  std::string equation;  // as the user wrote it
  bool from_file = false;
  HarmonicBalanceProblem problem;
  int default_order = 20;
  std::function<HarmonicSolution(int order)> guess;
  // The example's own index set for an order, when the default diamond or
  // box does not fit its spectrum (e.g. the asymmetric pendulum's beat).
  std::function<HarmonicBasis(int order)> basis_for_order;
  // The original equations with the base frequencies bound to `w` (forcing
  // terms need the solved values), and the state a solution predicts.
  std::function<integrators::OdeSystem(const std::vector<double>& w)> original;
  // Set instead of `original` for a model with algebraic equations: the DAE
  // F(t, y, y') = 0 for IDA.
  std::function<integrators::DaeSystem(const std::vector<double>& w)> original_dae;
  std::function<Eigen::VectorXd(const HarmonicSolution&, double t)> state;
  std::vector<std::string> state_names;
  // Every variable from the state and its derivatives on a torus.
  seeding::StateToVariables variables;
  int state_derivatives = 0;
  bool stiff = false;
  std::string original_error;  // why there is no original system, if so
  examples::Reference reference;
  std::string recast_report;   // the polynomial system, readable
  // Where the model starts (simulate, identify, analyze): its initial state,
  // or else the guess's state at t = 0 (the examples' guesses meet their
  // conditions). Empty only when there is no original system.
  Eigen::VectorXd initial_state;
  // Where each original state lives among the recast variables (examples:
  // state i is recast variable i), and how many of the problem's conditions
  // are the user's (the rest pin auxiliaries, METHOD.md eq. 24).
  std::vector<model::StateSource> state_sources;
  int num_user_conditions = 0;
  // The parsed model (model files only): for symbolic variants such as the
  // Taylor-expanded system.
  std::shared_ptr<const model::ModelDefinition> definition;
  model::ParameterValues overrides;
};

// A path (contains '/' or ends in .yaml/.yml, or names an existing file) is
// a model file; anything else an example name. Throws std::invalid_argument
// (unknown example/parameter) or model::ModelError (file:line:column).
ProblemSource LoadProblem(const std::string& model, const std::map<std::string, double>& overrides);

// The source's original equations integrated by what they need: IDA for a
// DAE, else CVODE (BDF when the source is stiff). One place for every command
// that integrates. Throw std::invalid_argument with original_error when the
// source has no original equations.
const char* OriginalIntegrator(const ProblemSource& source);  // "IDA BDF", "CVODE BDF", "CVODE Adams"
frequency_id::Signal RecordOriginal(const ProblemSource& source, const std::vector<double>& w,
                                    const Eigen::VectorXd& y0, const seeding::RecordOptions& record);
// The solution's state against a trajectory of the original equations from
// it at t = 0, over [0, t_end] (integrators/trajectory_validation.h).
integrators::ValidationReport ValidateOriginal(const ProblemSource& source, const HarmonicSolution& solution,
                                               double t_end);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_PROBLEM_SOURCE_H_

#include "rmhb/cli/problem_source.h"

#include <sys/stat.h>

#include <algorithm>
#include <memory>

#include "rmhb/model/model_definition.h"
#include "rmhb/model/recast.h"

namespace rmhb::cli {
namespace {

bool LooksLikeFile(const std::string& s) {
  auto ends = [&](const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  struct stat st;
  return s.find('/') != std::string::npos || ends(".yaml") || ends(".yml") ||
         (stat(s.c_str(), &st) == 0 && S_ISREG(st.st_mode));
}

ProblemSource FromExample(const std::string& name, const std::map<std::string, double>& overrides) {
  auto setup = std::make_shared<examples::ExampleSetup>(examples::BuildExample(name, overrides));
  ProblemSource p;
  p.name = name;
  p.equation = examples::FindExample(name)->equation;
  p.problem = setup->problem;
  p.default_order = setup->default_order;
  p.guess = [setup](int) { return setup->guess; };
  p.basis_for_order = setup->basis_for_order;
  p.original = [setup](const std::vector<double>&) {
    return integrators::OdeSystem{setup->original.dimension(), setup->original.rhs};
  };
  p.state = setup->original.state;
  p.state_names = setup->original.names;
  p.variables = [setup](const std::vector<double>&, const std::vector<Eigen::VectorXd>& y) {
    return setup->original.variables ? setup->original.variables(y[0]) : y[0];
  };
  p.stiff = setup->original.stiff;
  p.reference = setup->reference;
  p.recast_report = setup->problem.system.ToString();
  p.initial_state = setup->original.initial_state.size() ? setup->original.initial_state
                                                         : p.state(setup->guess, 0.0);
  for (int i = 0; i < setup->original.dimension(); ++i) p.state_sources.push_back({i, 0});
  int pins = 0;
  for (const auto& e : setup->problem.system.equations()) pins += e.balance_constant ? 0 : 1;
  p.num_user_conditions = static_cast<int>(setup->problem.conditions.size()) - pins;
  p.overrides = overrides;
  return p;
}

ProblemSource FromFile(const std::string& path, const std::map<std::string, double>& overrides) {
  const model::ModelDefinition definition = model::LoadModelFile(path);
  auto recast = std::make_shared<model::RecastResult>(model::Recast(definition, overrides));
  ProblemSource p;
  p.name = recast->model_name;
  p.from_file = true;
  for (const auto& e : definition.equations) p.equation += (p.equation.empty() ? "" : "; ") + e.text;
  p.problem = recast->problem;
  p.default_order = p.problem.frequencies.size() == 1 ? 25 : 7;
  p.guess = [recast](int order) { return recast->InitialGuess(order); };
  if (recast->original && recast->original->is_dae()) {
    p.original_dae = [recast](const std::vector<double>& w) {
      model::OriginalSystem bound = *recast->original;
      bound.BindFrequencies(w);
      return integrators::DaeSystem{bound.dimension, bound.residual, bound.differential};
    };
    // For commands that only integrate ODEs (they test `original`).
    p.original_error = "the original equations are a DAE (a variable appears without derivatives); "
                       "only IDA integrates them";
  } else if (recast->original) {
    p.original = [recast](const std::vector<double>& w) {
      model::OriginalSystem bound = *recast->original;
      bound.BindFrequencies(w);
      return integrators::OdeSystem{bound.dimension, bound.rhs};
    };
  }
  if (recast->original) {
    p.state = [recast](const HarmonicSolution& s, double t) {
      const std::vector<double> v = recast->original->StateFromSolution(s, t);
      return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<long>(v.size())).eval();
    };
    p.state_names = recast->original->state_names;
    // User variable v's derivative j: a state while j is below its order,
    // then the time derivative of its highest state.
    const std::vector<int> orders = recast->original->orders;
    for (size_t v = 0; v < orders.size(); ++v)
      p.state_derivatives = std::max(p.state_derivatives, recast->user_derivatives[v] - orders[v] + 1);
    p.variables = [recast, orders](const std::vector<double>& theta, const std::vector<Eigen::VectorXd>& y) {
      std::vector<double> user;
      int offset = 0;
      for (size_t v = 0; v < orders.size(); offset += orders[v], ++v)
        for (int j = 0; j <= recast->user_derivatives[v]; ++j)
          user.push_back(j < orders[v] ? y[0](offset + j) : y[j - orders[v] + 1](offset + orders[v] - 1));
      return recast->variables_from_user(theta, user);
    };
  } else {
    p.original_error = recast->original_error;
  }
  p.recast_report = recast->Report();
  if (recast->original) {
    p.state_sources = recast->original->sources;
    if (recast->initial_state)
      p.initial_state = Eigen::Map<const Eigen::VectorXd>(recast->initial_state->data(),
                                                          static_cast<long>(recast->initial_state->size()));
    else
      p.initial_state = p.state(p.guess(p.default_order), 0.0);
  }
  p.num_user_conditions = recast->num_user_conditions;
  p.definition = std::make_shared<const model::ModelDefinition>(definition);
  p.overrides = overrides;
  return p;
}

}  // namespace

ProblemSource LoadProblem(const std::string& model, const std::map<std::string, double>& overrides) {
  return LooksLikeFile(model) ? FromFile(model, overrides) : FromExample(model, overrides);
}

namespace {
void RequireOriginal(const ProblemSource& source) {
  if (!source.original && !source.original_dae)
    throw std::invalid_argument("cannot integrate the model: " + source.original_error);
}
}  // namespace

const char* OriginalIntegrator(const ProblemSource& source) {
  return source.original_dae ? "IDA BDF" : source.stiff ? "CVODE BDF" : "CVODE Adams";
}

frequency_id::Signal RecordOriginal(const ProblemSource& source, const std::vector<double>& w,
                                    const Eigen::VectorXd& y0, const seeding::RecordOptions& record) {
  RequireOriginal(source);
  return source.original_dae ? seeding::RecordTrajectory(source.original_dae(w), y0, record, source.state_names)
                             : seeding::RecordTrajectory(source.original(w), y0, record, source.state_names);
}

integrators::ValidationReport ValidateOriginal(const ProblemSource& source, const HarmonicSolution& solution,
                                               double t_end) {
  RequireOriginal(source);
  auto claimed = [&](double t) { return source.state(solution, t); };
  const std::vector<double>& w = solution.frequencies();
  return source.original_dae ? integrators::ValidateDaeTrajectory(source.original_dae(w), claimed, t_end)
                             : integrators::ValidateTrajectory(source.original(w), claimed, t_end, source.stiff);
}

}  // namespace rmhb::cli

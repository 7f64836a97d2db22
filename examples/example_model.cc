#include "examples/example_model.h"

#include <sys/stat.h>

#include <memory>

#include "examples/example_system.h"

namespace rmhb::examples {
namespace {

bool LooksLikeFile(const std::string& s) {
  auto ends = [&](const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  struct stat st;
  return s.find('/') != std::string::npos || ends(".yaml") || ends(".yml") ||
         (stat(s.c_str(), &st) == 0 && S_ISREG(st.st_mode));
}

}  // namespace

Model ExampleModel(const std::string& name, const std::map<std::string, double>& overrides) {
  auto setup = std::make_shared<ExampleSetup>(BuildExample(name, overrides));
  Model p;
  p.name = name;
  p.equation = FindExample(name)->equation;
  p.problem = setup->problem;
  p.default_order = setup->default_order;
  p.guess = [setup](int) { return setup->guess; };
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
  for (const Parameter& parameter : FindExample(name)->parameters)
    if (parameter.base >= 0) p.frequency_parameters[parameter.name] = parameter.base;
  p.reload = [name](const model::ParameterValues& values) { return ExampleModel(name, values); };
  DetectInvariances(&p);  // as LoadModel: the same symmetries for the same equations
  return p;
}

Model LoadModelOrExample(const std::string& name_or_path, const std::map<std::string, double>& overrides,
                         EquationsRoute route) {
  if (LooksLikeFile(name_or_path)) return LoadModel(name_or_path, overrides, route);
  // A bundled example is its hand-written recast.
  if (route == EquationsRoute::kOriginal)
    throw std::invalid_argument("--equations original: the bundled example '" + name_or_path +
                                "' is a hand-written recast; use its model file (examples/models/)");
  return ExampleModel(name_or_path, overrides);
}

}  // namespace rmhb::examples

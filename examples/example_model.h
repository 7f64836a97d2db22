#ifndef RMHB_EXAMPLES_EXAMPLE_MODEL_H_
#define RMHB_EXAMPLES_EXAMPLE_MODEL_H_

// The built-in examples (example_system.h: the paper's systems with their
// hand-written recasts, guesses and exact references) as Models, so that
// every study (rmhb/pipeline/) takes them as it takes a model file:
//   rmhb::Model pendulum = rmhb::examples::ExampleModel("pendulum", {{"a", 2}});
//   rmhb::Model any = rmhb::examples::LoadModelOrExample(argument, overrides);

#include <map>
#include <string>

#include "rmhb/pipeline/model.h"

namespace rmhb::examples {

// A built-in example with parameter overrides, its exact reference included.
// Throws std::invalid_argument naming an unknown example or parameter.
Model ExampleModel(const std::string& name, const std::map<std::string, double>& overrides = {});

// A path (contains '/' or ends in .yaml/.yml, or names an existing file) is
// a model file (rmhb::LoadModel); anything else an example name. Throws
// std::invalid_argument (unknown example/parameter) or model::ModelError
// (file:line:column).
// `route`: the equations a model file is solved on (rmhb/pipeline/model.h);
// kOriginal is refused for an example name (a hand-written recast).
Model LoadModelOrExample(const std::string& name_or_path, const std::map<std::string, double>& overrides = {},
                         EquationsRoute route = EquationsRoute::kRecast);

}  // namespace rmhb::examples

#endif  // RMHB_EXAMPLES_EXAMPLE_MODEL_H_

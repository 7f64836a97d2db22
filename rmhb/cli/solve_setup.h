#ifndef RMHB_CLI_SOLVE_SETUP_H_
#define RMHB_CLI_SOLVE_SETUP_H_

// The options every command that solves shares (solve, analyze, convergence,
// continuation, sweep): the model argument, --set, and the solve settings of
// the library (rmhb/pipeline/settings.h) they fill.

#include <map>
#include <string>
#include <vector>

#include "rmhb/pipeline/report.h"
#include "rmhb/pipeline/settings.h"

namespace CLI {
class App;
}

namespace rmhb::cli {

struct ModelSettings {
  std::string model;             // example name or model file
  std::vector<std::string> set;  // name=value
  SolveSettings solve;
};

// The model positional argument, --set and the solve settings' options.
void AddSolveSettings(CLI::App* app, ModelSettings* settings);

// The settings checked, the model loaded with --set (and `overrides` on top,
// e.g. a continuation parameter's value), then rmhb::PrepareSolve. Throws
// std::invalid_argument naming the bad value.
PreparedSolve Prepare(const ModelSettings& settings, const std::map<std::string, double>& overrides = {});

}  // namespace rmhb::cli

#endif  // RMHB_CLI_SOLVE_SETUP_H_

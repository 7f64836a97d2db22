#ifndef RMHB_CLI_CONTINUATION_COMMAND_H_
#define RMHB_CLI_CONTINUATION_COMMAND_H_

// `rmhb solve <model> --continue NAME=a:b`: follow the branch of solutions
// as a model parameter moves from a to b (rmhb/continuation.h) and print it:
// parameter, frequency, amplitude, residual, stability, folds.

#include <string>

#include "rmhb/cli/commands.h"

namespace CLI {
class App;
}

namespace rmhb::cli {

struct ContinuationArgs {
  std::string range;     // "NAME=a:b"; empty: no continuation
  int steps = 20;        // first step = |b - a| / steps
  double max_step = 0;   // 0: |b - a| / 10
  bool natural = false;  // natural-parameter instead of pseudo-arclength
  bool no_stability = false;
  std::string plot_var;  // with --plot: a variable's amplitude (default the first) or "frequency"
};

// Adds --continue, --steps, --max-step, --natural, --no-stability and --plot-var to `solve`.
void AddContinuationOptions(CLI::App* solve, ContinuationArgs* args);
// Runs the continuation with the solve command's settings and output flags.
int RunContinuation(const SolveArgs& solve, const ContinuationArgs& args);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_CONTINUATION_COMMAND_H_

#ifndef RMHB_CLI_CONVERGENCE_COMMAND_H_
#define RMHB_CLI_CONVERGENCE_COMMAND_H_

// `rmhb convergence`: for each order, solve with every method asked for and
// measure the error against an independent reference (the example's exact
// frequency / amplitude / solution, or else a tight CVODE trajectory of the
// original equations) and the run time: the paper's Tables 2 and 3 as one
// table of error against time, RHB, HDHB and HB-AFT side by side; for
// non-polynomial models also RHB on a Taylor-expanded system and HB-AFT on
// the original equations evaluated pointwise (no recast).

#include <string>

#include "rmhb/cli/solve_setup.h"

namespace CLI {
class App;
}

namespace rmhb::cli {

struct ConvergenceArgs {
  ModelSettings settings;            // model, --set, --frequencies, ...
  std::string orders = "5:25:5";     // start:stop:step or a list
  std::string methods;               // "": rhb,hdhb,aft (+ taylor,original)
  std::string solvers;               // "": the default solver
  std::string conditions = "model";  // model, scheme1, scheme2, scheme3 (a list)
  int taylor_order = 15;
  int original_samples = 0;          // 0: the recast system's HB-AFT count
  int repeat = 1;
  double max_seconds = 60;
  std::string plot;
  bool json = false;
};

void AddConvergenceOptions(CLI::App* app, ConvergenceArgs* args);
int RunConvergence(const ConvergenceArgs& args);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_CONVERGENCE_COMMAND_H_

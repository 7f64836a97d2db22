#ifndef RMHB_CLI_SIMULATE_COMMAND_H_
#define RMHB_CLI_SIMULATE_COMMAND_H_

// `rmhb simulate`: the ORIGINAL equations of a model integrated by SUNDIALS
// CVODE from the model's initial state, sampled every dt, as CSV (t and
// every state). The transient a harmonic balance solution leaves out is
// visible here, and the same integrator is the reference for convergence.

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace rmhb::cli {

struct SimulateArgs {
  std::string model;
  std::vector<std::string> set;
  double t_end = 0;  // unless given: 20 periods of the slowest base frequency
  double dt = 0;     // unless given: a 64th of the fastest period
  bool t_end_given = false, dt_given = false;
  double rtol = 1e-12;
  double atol = 1e-14;
  std::string integrator = "auto";  // auto, adams, bdf
  std::string csv;                  // "": to standard output (text mode)
  std::string plot;
  bool json = false;
};

void AddSimulateOptions(CLI::App* app, SimulateArgs* args);
int RunSimulate(const SimulateArgs& args);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_SIMULATE_COMMAND_H_

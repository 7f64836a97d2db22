#ifndef RMHB_CLI_MONTECARLO_COMMAND_H_
#define RMHB_CLI_MONTECARLO_COMMAND_H_

// `rmhb montecarlo`: the paper's Table 1 experiment on any periodic model:
// random starts solved by RHB and HDHB, the distinct solutions each finds,
// classified physical-stable, physical-unstable or non-physical (library:
// rmhb/monte_carlo.h), stability by Hill's method and by the Floquet
// multipliers of the original equations (integrators/floquet.h).

#include <cstdint>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace rmhb::cli {

struct MonteCarloArgs {
  std::string model;
  std::vector<std::string> set;
  int order = 3;
  std::string solver = "auto";
  int max_iterations = 100;
  long starts = 10000;
  std::string range = "-2:2";
  std::uint64_t seed = 1;
  int threads = 0;
  int reference_order = 0;
  double match_tolerance = 0.05;
  std::string methods = "rhb,hdhb";
  bool no_floquet = false;
  bool json = false;
};

void AddMonteCarloOptions(CLI::App* app, MonteCarloArgs* args);
// Every MPI rank runs it (ranks = 1 without mpirun); rank 0 prints.
int RunMonteCarlo(const MonteCarloArgs& args, int rank = 0, int ranks = 1);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_MONTECARLO_COMMAND_H_

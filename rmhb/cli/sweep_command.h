#ifndef RMHB_CLI_SWEEP_COMMAND_H_
#define RMHB_CLI_SWEEP_COMMAND_H_

// `rmhb sweep MODEL --grid NAME=a:b:n [--grid ...]`: every steady state at
// every point of a parameter grid, on one process or many (`mpirun -n R
// rmhb sweep ...`), checkpointed as it goes and resumable (--resume), into
// one HDF5 file (library: rmhb/sweep/).

#include <cstdint>
#include <string>
#include <vector>

#include "rmhb/cli/solve_setup.h"

namespace CLI {
class App;
}

namespace rmhb::cli {

struct SweepArgs {
  ModelSettings settings;
  std::vector<std::string> grid;
  int starts = 8;
  std::string range = "-2:2";
  std::uint64_t seed = 1;
  std::string out = "sweep.h5";
  bool resume = false;
  bool keep_journal = false;
  bool no_stability = false;
  std::string log;
  std::string plot;
  std::string plot_value = "amplitude";
  bool json = false;
};

void AddSweepOptions(CLI::App* app, SweepArgs* args);
// Every rank runs it; rank 0 prints. `rank`, `ranks`: MPI_COMM_WORLD's.
int RunSweep(const SweepArgs& args, int rank, int ranks);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_SWEEP_COMMAND_H_

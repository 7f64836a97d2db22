#ifndef RMHB_CLI_ANALYZE_COMMAND_H_
#define RMHB_CLI_ANALYZE_COMMAND_H_

// `rmhb analyze`: the whole pipeline on a model, each stage timed and checked:
//   trajectory (CVODE on the original equations) -> identify (base
//   frequencies, labelled lines) -> seed (the guess on the RMHB basis) ->
//   solve (RHB for one base, RMHB for several) -> validate (the solution
//   against a SUNDIALS trajectory of the original equations).
// With --frequencies the first three are skipped: the model's own guess at
// those frequencies starts the solve, as in `rmhb solve`.

#include "rmhb/cli/solve_setup.h"

namespace CLI {
class App;
}

namespace rmhb::cli {

struct AnalyzeArgs {
  ModelSettings settings;
  double t_end = 0;        // 0: from the model's frequencies
  double transient = -1;   // -1: a tenth of t_end
  int samples_per_period = 0;  // 0: from the basis's highest harmonic
  int window = 0;          // Hann^q, 0 = automatic
  int validate_periods = 20;
  double validate_tol = 1e-8;  // relative to max|state|; above it: exceeds, exit 6
  std::string plot;        // FILE.png|svg: the solution against CVODE
  bool json = false;
};

void AddAnalyzeOptions(CLI::App* app, AnalyzeArgs* args);
int RunAnalyze(const AnalyzeArgs& args);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_ANALYZE_COMMAND_H_

// rmhb: the command-line front end. Thin by design: it parses arguments,
// builds a problem from the examples (or a model file), calls the library,
// and prints a report (text or --json). Exit codes: see exit_codes.h.

#include <CLI/CLI.hpp>

#include <cstdio>
#include <functional>
#include <iostream>
#include <stdexcept>

#include "rmhb/version.h"
#include "rmhb/cli/commands.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/model/model_error.h"

#ifdef RMHB_CLI_PARALLEL
#include "rmhb/sweep/mpi.h"
#else
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#endif

namespace {

#ifdef RMHB_CLI_PARALLEL

// Sweeps and censuses run on every MPI rank (one without mpirun): an error
// on one stops them all (a rank that only returned would leave the others
// waiting for it forever).
int RunOnEveryRank(const std::function<int(int rank, int ranks)>& command, int argc, char** argv) {
  using namespace rmhb::cli;
  rmhb::sweep::MpiSession mpi(&argc, &argv);
  int code = kExitInternal;
  try {
    return command(mpi.rank(), mpi.size());
  } catch (const rmhb::model::ModelError& e) {
    if (mpi.rank() == 0) std::fprintf(stderr, "rmhb: error: %s\n", e.what());
    code = kExitBadInput;
  } catch (const std::invalid_argument& e) {
    if (mpi.rank() == 0) std::fprintf(stderr, "rmhb: error: %s\n", e.what());
    code = kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rmhb: internal error (rank %d): %s\n", mpi.rank(), e.what());
  }
  if (mpi.size() > 1) rmhb::sweep::AbortAll(code);
  return code;
}

#else

// sweep and montecarlo: this process becomes rmhb-parallel, from the same
// directory, with the same arguments (and, under mpirun, the same rank).
int ExecParallel(char** argv) {
  std::string path(4096, '\0');
  const ssize_t n = readlink("/proc/self/exe", path.data(), path.size() - 1);
  path.resize(n > 0 ? static_cast<size_t>(n) : 0);
  path = path.substr(0, path.rfind('/') + 1) + "rmhb-parallel";
  execv(path.c_str(), argv);
  std::fprintf(stderr, "rmhb: internal error: `%s` runs in %s, which could not be started: %s\n", argv[1],
               path.c_str(), std::strerror(errno));
  return rmhb::cli::kExitInternal;
}

#endif

}  // namespace

int main(int argc, char** argv) {
  using namespace rmhb::cli;
  CLI::App app{
      "rmhb: periodic and quasi-periodic steady states of nonlinear dynamical systems by\n"
      "reconstruction harmonic balance (RHB), to machine precision.\n\n"
      "Exit codes: 0 ok, 1 usage error, 2 bad input (unknown model or parameter, invalid\n"
      "value, gnuplot missing for --plot), 3 the solver did not converge (the residual\n"
      "reached is reported) or an integration stopped early, 4 internal, 5 converged to a\n"
      "NON-PHYSICAL solution (an auxiliary off its definition between the samples, e.g. the\n"
      "wrong root of a sqrt recast or aliasing, or an unknown frequency collapsed to w <= 0),\n"
      "6 validated (--validate) with an error above --validate-tol.\n"
      "`rmhb <command> --help` describes each command, its options and defaults."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rmhb " RMHB_VERSION_STRING);

  SolveArgs solve;
  CLI::App* solve_cmd = app.add_subcommand(
      "solve",
      "Solve for a periodic or quasi-periodic steady state of an example or model file.\n"
      "Prints the frequency, the harmonic coefficients and, with --validate, the maximum\n"
      "error against a SUNDIALS integration of the ORIGINAL equations.");
  AddSolveOptions(solve_cmd, &solve);
  ContinuationArgs continuation;
  AddContinuationOptions(solve_cmd, &continuation);

  RecastArgs recast;
  CLI::App* recast_cmd = app.add_subcommand(
      "recast", "Print the polynomial (recast) system of an example or model file: variables,\n"
                "definitions of the auxiliaries, equations, conditions and the degree phi.");
  AddRecastOptions(recast_cmd, &recast);

  IdentifyArgs identify;
  CLI::App* identify_cmd = app.add_subcommand(
      "identify", "Find the base frequencies and label every spectral component (m, n), from a\n"
                  "sampled signal (--signal FILE.csv) or from a model's integrated trajectory.");
  AddIdentifyOptions(identify_cmd, &identify);

  MonteCarloArgs montecarlo;
  CLI::App* montecarlo_cmd = app.add_subcommand(
      "montecarlo", "Random starts solved by RHB and HDHB: the distinct solutions each finds, classified\n"
                    "physical-stable, physical-unstable or non-physical (the paper's Table 1).");
  AddMonteCarloOptions(montecarlo_cmd, &montecarlo);

  SimulateArgs simulate;
  CLI::App* simulate_cmd = app.add_subcommand(
      "simulate", "Integrate the ORIGINAL equations with SUNDIALS CVODE from the model's initial\n"
                  "state; write t and every state as CSV.");
  AddSimulateOptions(simulate_cmd, &simulate);

  ConvergenceArgs convergence;
  CLI::App* convergence_cmd = app.add_subcommand(
      "convergence", "Error against run time for each order: RHB, HDHB and HB-AFT side by side,\n"
                     "and for non-polynomial models RHB-Taylor and HB-AFT on the original equations.");
  AddConvergenceOptions(convergence_cmd, &convergence);

  AnalyzeArgs analyze;
  CLI::App* analyze_cmd = app.add_subcommand(
      "analyze", "Integrate, identify the base frequencies, seed and solve RHB/RMHB, validate:\n"
                 "every stage's error and run time in one report. --frequencies skips identification.\n"
                 "Exit 3 when the identification or the solve fails (status says which), 5 when the\n"
                 "solve converges to a non-physical solution.");
  AddAnalyzeOptions(analyze_cmd, &analyze);

  SweepArgs sweep;
  CLI::App* sweep_cmd = app.add_subcommand(
      "sweep", "Every steady state at every point of a parameter grid (--grid NAME=a:b:n, repeatable):\n"
               "continuation along the first axis plus random starts, stability, one HDF5 file;\n"
               "checkpointed and resumable (--resume); over MPI with `mpirun -n R rmhb sweep ...`.");
  AddSweepOptions(sweep_cmd, &sweep);

  CLI::App* list_cmd = app.add_subcommand("list", "List the bundled examples and their parameters.");
  bool list_json = false;
  list_cmd->add_flag("--json", list_json, "Machine-readable output: name, description, equation, parameters");
  list_cmd->footer("Exit codes: 0 ok, 1 usage.");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsage;
  }
#ifdef RMHB_CLI_PARALLEL
  if (*sweep_cmd) return RunOnEveryRank([&](int rank, int ranks) { return RunSweep(sweep, rank, ranks); }, argc, argv);
  if (*montecarlo_cmd)
    return RunOnEveryRank([&](int rank, int ranks) { return RunMonteCarlo(montecarlo, rank, ranks); }, argc, argv);
#else
  if (*sweep_cmd || *montecarlo_cmd) return ExecParallel(argv);
#endif
  try {
    if (*solve_cmd && continuation.range.empty()) CheckWithoutContinuation(continuation);
    if (*solve_cmd) return continuation.range.empty() ? RunSolve(solve) : RunContinuation(solve, continuation);
    if (*list_cmd) return RunList(list_json);
    if (*recast_cmd) return RunRecast(recast);
    if (*identify_cmd) return RunIdentify(identify);
    if (*simulate_cmd) return RunSimulate(simulate);
    if (*convergence_cmd) return RunConvergence(convergence);
    if (*analyze_cmd) return RunAnalyze(analyze);
  } catch (const rmhb::model::ModelError& e) {
    std::fprintf(stderr, "rmhb: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "rmhb: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rmhb: internal error: %s\n", e.what());
    return kExitInternal;
  }
  return kExitUsage;
}

#ifndef RMHB_CLI_COMMANDS_H_
#define RMHB_CLI_COMMANDS_H_

// The commands of the tool. Each parses its options into an Args, fills the
// library's Options from them, calls the library (rmhb/pipeline/, the study
// of the same name) and prints its summary: text, --json (the summary's
// ToJson() with the command line's own fields), CSV, --plot (rmhb/plot/).
// Exit codes: exit_codes.h.

#include <cstdint>
#include <string>
#include <vector>

#include "rmhb/cli/solve_setup.h"

namespace CLI {
class App;
}

namespace rmhb::cli {

struct SolveArgs {
  ModelSettings settings;
  bool validate = false;
  bool stability = false;   // Floquet multipliers by Hill's method and CVODE
  int validate_periods = 1;
  double validate_tol = 1e-8;  // relative to max|state|: above it the validation EXCEEDS (exit 6)
  bool json = false;
  bool quiet = false;
  std::string eval;         // "t0:dt:t1"
  std::string csv;          // file for --eval
  std::string plot;         // FILE.png|svg: response, error, phase portrait
  std::string start = "auto";  // auto: the guess, then a simulated/identified start; guess: the guess only
};

struct RecastArgs {
  std::string model;
  std::vector<std::string> set;
  bool json = false;
};

void AddSolveOptions(CLI::App* app, SolveArgs* args);
int RunSolve(const SolveArgs& args);
int RunList(bool json);
void AddRecastOptions(CLI::App* app, RecastArgs* args);
int RunRecast(const RecastArgs& args);

// `rmhb solve <model> --continue NAME=a:b`: follow the branch of solutions
// as a model parameter moves from a to b (rmhb/pipeline/branch.h) and print it:
// parameter, frequency, amplitude, residual, Floquet multipliers and
// stability (Hill or the monodromy), folds, branch points, period doublings
// and Neimark-Sacker points; with --switch-branches the period-2T branch
// from every period doubling and the torus at every Neimark-Sacker point.
struct ContinuationArgs {
  std::string range;     // "NAME=a:b"; empty: no continuation
  int steps = 20;        // first step = |b - a| / steps
  double max_step = 0;   // 0: |b - a| / 10
  bool natural = false;  // natural-parameter instead of pseudo-arclength
  bool no_stability = false;
  std::string stability_method = "auto";  // auto, hill, monodromy
  bool stability_method_given = false;
  bool switch_branches = false;
  std::string plot_var;  // with --plot: a variable's amplitude (default the first) or "frequency"
  double torus_tail = 1e-6;   // ContinueOptions::tail_tolerance
  bool torus_tail_given = false;
  bool no_locking = false;    // !ContinueOptions::locking
};

// Adds --continue, --steps, --max-step, --natural, --no-stability,
// --stability-method, --switch-branches, --plot-var, --torus-tail and
// --no-locking to `solve`.
void AddContinuationOptions(CLI::App* solve, ContinuationArgs* args);
// Throws std::invalid_argument when an option only continuation uses is
// given without --continue.
void CheckWithoutContinuation(const ContinuationArgs& args);
// Runs the continuation with the solve command's settings and output flags.
int RunContinuation(const SolveArgs& solve, const ContinuationArgs& args);

// `rmhb analyze`: the whole pipeline on a model, each stage timed and checked:
//   trajectory (CVODE on the original equations) -> identify (base
//   frequencies, labelled lines) -> seed (the guess on the RMHB basis) ->
//   solve (RHB for one base, RMHB for several) -> validate (the solution
//   against a SUNDIALS trajectory of the original equations).
// With --frequencies the first three are skipped: the model's own guess at
// those frequencies starts the solve, as in `rmhb solve`.
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

// `rmhb identify`: base frequencies and labelled components, from a user's
// sampled signal (CSV) or from a model's trajectory (CVODE on the original
// equations, the transient discarded).
struct IdentifyArgs {
  std::string model;
  std::string signal;  // CSV file: t, channel...
  std::vector<std::string> set;
  double t_end = 0;      // 0: chosen from the guessed frequencies
  double transient = -1; // -1: a tenth of the record
  int samples_per_period = 0;
  int window = 0;        // Hann^q order, 0 = automatic
  std::string plot;      // spectrum with labelled lines, FILE.png|svg
  bool json = false;
};

void AddIdentifyOptions(CLI::App* app, IdentifyArgs* args);
int RunIdentify(const IdentifyArgs& args);

// `rmhb simulate`: the ORIGINAL equations of a model integrated by SUNDIALS
// CVODE from the model's initial state, sampled every dt, as CSV (t and
// every state). The transient a harmonic balance solution leaves out is
// visible here, and the same integrator is the reference for convergence.
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

// `rmhb convergence`: for each order, solve with every method asked for and
// measure the error against an independent reference (the example's exact
// frequency / amplitude / solution, or else a tight CVODE trajectory of the
// original equations) and the run time: the paper's Tables 2 and 3 as one
// table of error against time, RHB, HDHB and HB-AFT side by side; for
// non-polynomial models also RHB on a Taylor-expanded system and HB-AFT on
// the original equations evaluated pointwise (no recast).
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

// `rmhb montecarlo`: the paper's Table 1 experiment on any periodic model:
// random starts solved by RHB and HDHB, the distinct solutions each finds,
// classified physical-stable, physical-unstable or non-physical (library:
// rmhb/pipeline/census.h), stability by Hill's method and by the Floquet
// multipliers of the original equations (integrators/floquet.h).
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

// `rmhb sweep MODEL --grid NAME=a:b:n [--grid ...]`: every steady state at
// every point of a parameter grid, on one process or many (`mpirun -n R
// rmhb sweep ...`), checkpointed as it goes and resumable (--resume), into
// one HDF5 file (library: rmhb/sweep/).
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

#endif  // RMHB_CLI_COMMANDS_H_

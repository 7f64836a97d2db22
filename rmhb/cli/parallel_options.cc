// The options of the commands that run over MPI and write HDF5 (sweep,
// montecarlo): parsed by both binaries, run by rmhb-parallel only (main.cc).

#include <CLI/CLI.hpp>

#include "rmhb/cli/commands.h"

namespace rmhb::cli {

void AddMonteCarloOptions(CLI::App* app, MonteCarloArgs* a) {
  app->add_option("model", a->model, "Example name (see `rmhb list`) or model file; periodic only")
      ->required();
  app->add_option("--set", a->set, "Override a parameter: --set name=value (repeatable)");
  app->add_option("--order,-N", a->order, "Harmonic order N of every solve (default 3)");
  app->add_option("--starts", a->starts, "Number of random starts (default 10000)");
  app->add_option("--range", a->range,
                  "Every unknown coefficient of a start is uniform in lo:hi (default -2:2)");
  app->add_option("--seed", a->seed, "Random seed; the result depends on it only, not on --threads (default 1)");
  app->add_option("--threads", a->threads, "Worker threads (default 0: all cores)");
  app->add_option("--methods", a->methods, "Sampling rules to compare, from rhb, hdhb, aft (default rhb,hdhb)");
  app->add_option("--reference-order", a->reference_order,
                  "Order of the alias-free solve that decides physical (default max(40, 8 N))");
  app->add_option("--match-tolerance", a->match_tolerance,
                  "Largest relative distance to its reference solve for a solution to count as "
                  "physical (default 0.05)");
  app->add_option("--solver", a->solver, "newton, lm, tikhonov or auto (default: Newton, then L-M)")
      ->check(CLI::IsMember({"auto", "newton", "lm", "tikhonov"}));
  app->add_option("--max-iterations", a->max_iterations, "Iteration limit per start (default 100)")
      ->check(CLI::Range(1, 100000));
  app->add_flag("--no-floquet", a->no_floquet,
                "Skip the Floquet multipliers of the original equations (CVODE)");
  app->add_flag("--json", a->json, "Machine-readable output");
}

void AddSweepOptions(CLI::App* app, SweepArgs* a) {
  AddSolveSettings(app, &a->settings);
  app->add_option("--grid", a->grid,
                  "A parameter axis NAME=a:b:n, n values from a to b (repeatable; the first axis "
                  "runs fastest and is the continuation direction)")
      ->required();
  app->add_option("--starts", a->starts, "Random starts per point, besides continuation (default 8)")
      ->check(CLI::Range(0, 1000000));
  app->add_option("--range", a->range, "Every coefficient of a random start is uniform in lo:hi (default -2:2)");
  app->add_option("--seed", a->seed, "Random seed (default 1); results depend on it, not on the ranks");
  app->add_option("--out", a->out, "The HDF5 result file (default sweep.h5); its journal is OUT.journal/");
  app->add_flag("--resume", a->resume,
                "Finish an interrupted sweep from OUT.journal/ without recomputing finished points");
  app->add_flag("--keep-journal", a->keep_journal, "Keep OUT.journal/ after the file is written");
  app->add_flag("--no-stability", a->no_stability, "Skip Hill's stability verdict per solution");
  app->add_option("--log", a->log, "Append one line per computed point (index, rank, status, time) to FILE");
  app->add_option("--plot", a->plot, "A heat map of the first two axes (PNG or SVG by extension)");
  app->add_option("--plot-value", a->plot_value, "What --plot shows: amplitude (largest, default) or count")
      ->check(CLI::IsMember({"amplitude", "count"}));
  app->add_flag("--json", a->json, "Machine-readable summary");
  app->footer(
      "Over MPI: mpirun -n R rmhb sweep ... (rank 0 hands out grid lines, the others solve them).\n"
      "Exit codes: 0 the file is written (failed points are recorded in it), 1 usage, 2 bad input\n"
      "(unknown parameter, bad --grid, a journal of another sweep, OUT.journal/ exists without\n"
      "--resume), 4 internal.");
}

}  // namespace rmhb::cli

#include "rmhb/cli/commands.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "rmhb/cli/exit_codes.h"
#include "rmhb/pipeline/census.h"
#include "rmhb/sweep/monte_carlo_mpi.h"

namespace rmhb::cli {
namespace {

// A progress bar on stderr, only for a person watching a terminal.
void ShowProgress(long done, long total) {
  const int width = 40;
  const long step = std::max(1L, total / 200);
  if (done % step != 0 && done != total) return;
  const int filled = static_cast<int>(width * done / total);
  std::fprintf(stderr, "\r[%.*s%*s] %3d%% %ld/%ld starts", filled,
               "########################################", width - filled, "",
               static_cast<int>(100 * done / total), done, total);
  if (done == total) std::fprintf(stderr, "\r%*s\r", width + 40, "");
}

}  // namespace

void AddMonteCarloOptions(CLI::App* app, MonteCarloArgs* a) {
  app->add_option("model", a->model, "Example name (see `rmhb list`) or model file; periodic only")
      ->required();
  app->add_option("--set", a->set, "Override a parameter: --set name=value (repeatable)");
  app->add_option("--order,-N", a->order, "Harmonic order N of every solve (default 3)");
  app->add_option("--starts", a->starts, "Number of random starts (default 10000)");
  app->add_option("--range", a->range,
                  "Every coefficient of a start is uniform in lo:hi (default -2:2)");
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

int RunMonteCarlo(const MonteCarloArgs& a, int rank, int ranks) {
  ModelSettings settings;
  settings.model = a.model;
  settings.set = a.set;
  settings.solve.order = a.order;
  settings.solve.solver = a.solver;
  settings.solve.max_iterations = a.max_iterations;
  const PreparedSolve prepared = Prepare(settings);
  const std::vector<double> range = ParseNumberList(a.range, "--range");
  if (range.size() != 2 || !(range[0] < range[1]))
    throw std::invalid_argument("--range expects lo:hi with lo < hi, got '" + a.range + "'");
  CensusOptions options;
  MonteCarloOptions& mc = options.monte_carlo;
  mc.starts = a.starts;
  mc.low = range[0];
  mc.high = range[1];
  mc.seed = a.seed;
  mc.threads = a.threads;
  mc.reference_order = a.reference_order;
  mc.match_tolerance = a.match_tolerance;
  mc.solve = prepared.options;
  mc.rules.clear();
  std::stringstream methods(a.methods + ",");
  for (std::string item; std::getline(methods, item, ',');) mc.rules.push_back(ParseSamplingRule(item));
  if (isatty(STDERR_FILENO) && rank == 0) mc.progress = ShowProgress;
  options.floquet = !a.no_floquet;
  CensusSummary summary = Census(prepared.model, options, [&](const HarmonicBalanceProblem& p, const MonteCarloOptions& o) {
    return sweep::DistributedMonteCarlo(p, o, rank, ranks);
  });
  if (rank != 0) return kExitOk;
  summary.ranks = ranks;
  if (a.json) {
    nlohmann::json out = summary.ToJson();
    out["model"] = a.model;
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("%s: %s\n%s", prepared.model.name.c_str(), prepared.model.equation.c_str(), summary.FullReport().c_str());
  }
  if (summary.status == CensusStatus::kNoneConverged) {
    std::fprintf(stderr, "rmhb: not converged: a method converged from none of the %ld starts\n",
                 summary.monte_carlo.starts);
    return kExitNotConverged;
  }
  return kExitOk;
}

}  // namespace rmhb::cli

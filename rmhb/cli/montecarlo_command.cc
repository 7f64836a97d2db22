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

// The library call behind tests/benchmarks/peers/bench: one model file solved at
// one order on the chosen equations (recast, original, auto), from the model's
// guess with the default options, as `rmhb solve` does. Prints one JSON line:
// the model's load time (parse, recast, compile the original equations), the
// first solve in the process (cold: tables, plans, first touches) and the
// median of warm solves.
//   peer_problems_benchmark MODEL.yaml ORDER [recast|original|auto]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/model.h"

namespace {

double Since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s MODEL.yaml ORDER [recast|original|auto]\n", argv[0]);
    return 2;
  }
  const auto t0 = std::chrono::steady_clock::now();
  rmhb::Model model =
      rmhb::LoadModel(argv[1], {}, rmhb::ParseEquationsRoute(argc > 3 ? argv[3] : "recast"));
  const double load = Since(t0);
  rmhb::HarmonicBalanceOptions options;
  options.order = std::stoi(argv[2]);
  const rmhb::HarmonicSolution guess = rmhb::GuessAtOrder(model, options.order);
  const int symmetries = rmhb::ImposeGuessSymmetries(guess, &model);  // as `rmhb solve` does
  const auto t1 = std::chrono::steady_clock::now();
  rmhb::HarmonicBalanceSummary s = rmhb::SolveHarmonicBalance(model.problem, guess, options);
  const double cold = Since(t1);
  std::vector<double> times;
  const auto begin = std::chrono::steady_clock::now();
  while (times.size() < 5 || (times.size() < 2000 && Since(begin) < 1.0)) {
    const auto t = std::chrono::steady_clock::now();
    s = rmhb::SolveHarmonicBalance(model.problem, guess, options);
    times.push_back(Since(t));
  }
  std::sort(times.begin(), times.end());
  std::printf(
      "{\"load_seconds\": %.9g, \"cold_seconds\": %.9g, \"warm_seconds\": %.9g, \"repeats\": %zu, "
      "\"status\": \"%s\", \"iterations\": %d, \"unknowns\": %d, \"equations\": \"%s\", "
      "\"symmetries\": %d}\n",
      load, cold, times[times.size() / 2], times.size(), s.usable() ? "usable" : "not usable",
      s.solver.iterations, s.solver.num_unknowns, model.equations.c_str(), symmetries);
  return s.usable() ? 0 : 1;
}

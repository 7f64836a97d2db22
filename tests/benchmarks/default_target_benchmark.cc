// The default accuracy target (1e-10, METHOD.md s.8) against the cheapest
// fixed order that meets it: what automatic order selection costs over
// knowing the order in advance. Periodic models: the default solve (its
// order chosen from the coefficient tail, calibrated on a lower order)
// against fixed orders from the model's guess, each measured against a
// solve at twice the chosen order + 20 (SolutionDifference: coefficients
// and frequency); the cheapest fixed order within 1e-10 is timed alone.
// Quasi-periodic models: the default solve (adaptive index set) against a
// solve on its final index set alone from the same guess, both measured
// against CVODE over 1000 time units. Median wall time of 5 runs.
//   build/tests/benchmarks/default_target_benchmark [model ...]

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "examples/example_model.h"
#include "rmhb/pipeline/settings.h"
#include "rmhb/pipeline/solve.h"

namespace {

using namespace rmhb;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double Time(const std::function<void()>& run, int repeats = 5) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const auto begin = std::chrono::steady_clock::now();
    run();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count());
  }
  return Median(t);
}

HarmonicBalanceSummary Solve(const Model& model, const HarmonicSolution& guess, const HarmonicBalanceOptions& o) {
  return SolveHarmonicBalance(model.problem, guess, o);
}

void Periodic(const std::string& name, const std::map<std::string, double>& overrides = {},
              const std::string& quantity = "state") {
  SolveSettings settings;
  settings.default_tol = SolveSettings::kDefaultTolerance;
  settings.tol_quantity = quantity;
  const PreparedSolve p = PrepareSolve(examples::LoadModelOrExample(name.substr(0, name.find(" ")), overrides), settings);
  HarmonicBalanceSummary chosen;
  const double t_default = Time([&] { chosen = Solve(p.model, p.guess, p.options); });
  if (!chosen.converged()) {
    std::printf("%-34s default solve failed: %s\n", name.c_str(), chosen.solver.message.c_str());
    return;
  }
  HarmonicBalanceOptions fixed = p.options;
  fixed.tolerance = 0;
  fixed.order = 2 * chosen.order + 20;
  const HarmonicBalanceSummary reference = Solve(p.model, p.guess, fixed);
  auto error = [&](const HarmonicSolution& s) {
    if (quantity == "state") return SolutionDifference(s, *reference.solution);
    const double w = reference.solution->frequencies()[0];
    return std::abs(s.frequencies()[0] - w) / w;
  };
  const double error_default = error(*chosen.solution);
  // The smallest order within 1e-10, by bisection (the error falls with the order).
  int lo = std::max(2, chosen.order / 4), hi = 2 * chosen.order, cheapest = -1;
  double error_cheapest = 0;
  while (lo <= hi) {
    fixed.order = (lo + hi) / 2;
    const HarmonicBalanceSummary s = Solve(p.model, p.guess, fixed);
    const double e = s.converged() ? error(*s.solution) : INFINITY;
    if (e <= 1e-10)
      cheapest = fixed.order, error_cheapest = e, hi = fixed.order - 1;
    else
      lo = fixed.order + 1;
  }
  fixed.order = cheapest;
  const double t_fixed = Time([&] { Solve(p.model, p.guess, fixed); });
  // Before the default target: the model's default order, fixed.
  fixed.order = p.options.order;
  HarmonicBalanceSummary before;
  const double t_before = Time([&] { before = Solve(p.model, p.guess, fixed); });
  const double error_before = before.converged() ? error(*before.solution) : NAN;
  std::string orders;
  for (int o : chosen.orders_tried) orders += (orders.empty() ? "" : " ") + std::to_string(o);
  std::printf("%-30s N %4d (orders %-16s) %.1e %8.2f ms | cheapest N %4d %.1e %8.2f ms | ratio %.2f | "
              "before: N %d %.1e %8.2f ms\n",
              name.c_str(), chosen.order, orders.c_str(), error_default, t_default * 1e3, cheapest, error_cheapest,
              t_fixed * 1e3, t_default / t_fixed, p.options.order, error_before, t_before * 1e3);
}

void QuasiPeriodic(const std::string& name) {
  SolveSettings settings;
  settings.default_tol = SolveSettings::kDefaultTolerance;
  PreparedSolve p = PrepareSolve(examples::LoadModelOrExample(name), settings);
  ImposeGuessSymmetries(p.guess, &p.model);
  HarmonicBalanceSummary chosen;
  const double t_default = Time([&] { chosen = Solve(p.model, p.guess, p.options); }, 3);
  if (!chosen.converged()) {
    std::printf("%-34s default solve failed: %s\n", name.c_str(), chosen.solver.message.c_str());
    return;
  }
  const HarmonicBasis basis = chosen.solution->basis();
  HarmonicBalanceOptions fixed = p.options;
  fixed.tolerance = 0;
  fixed.basis_for_order = [basis](int) { return basis; };
  HarmonicBalanceSummary alone;
  const double t_fixed = Time([&] { alone = Solve(p.model, p.guess, fixed); }, 3);
  const double t_end = 1000;
  auto error = [&](const HarmonicBalanceSummary& s) {
    return s.converged() ? ValidateOriginal(p.model, *s.solution, t_end, 4001).max_error : NAN;
  };
  std::printf("%-34s %4d harmonics, %zu symmetries, %.1e over [0, %g] %8.1f ms | that set alone %.1e %8.1f ms | "
              "ratio %.2f\n",
              name.c_str(), basis.size(), p.model.problem.symmetries.size(), error(chosen), t_end, t_default * 1e3,
              error(alone), t_fixed * 1e3, t_default / t_fixed);
}

}  // namespace

int main(int argc, char** argv) {
  auto run = [&](const std::string& name) {
    if (argc < 2) return true;
    for (int i = 1; i < argc; ++i)
      if (name.find(argv[i]) != std::string::npos) return true;
    return false;
  };
  std::printf("default target 1e-10 against the cheapest fixed order within 1e-10 (median wall time)\n");
  for (const char* name : {"pendulum", "duffing", "relativistic", "tests/pipeline/models/exp-oscillator.yaml",
                           "tests/pipeline/models/radical-oscillator.yaml", "examples/models/pendulum.yaml"})
    if (run(name)) Periodic(name);
  if (run("pendulum theta0=3")) Periodic("pendulum theta0=3", {{"theta0", 3.0}});
  if (run("vanderpol eps=10")) Periodic("vanderpol eps=10", {{"eps", 10.0}});
  if (run("vanderpol eps=10 frequency")) Periodic("vanderpol eps=10 frequency", {{"eps", 10.0}}, "frequency");
  for (const char* name : {"examples/models/asym-pendulum.yaml", "examples/models/forced-vanderpol.yaml"})
    if (run(name)) QuasiPeriodic(name);
  return 0;
}

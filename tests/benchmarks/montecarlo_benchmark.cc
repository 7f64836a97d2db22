// The paper's Table 1 (rmhb/METHOD.md s.3) on the forced Duffing oscillator
// x'' + 0.1 x' + x + x^3 = cos(2 t), where three periodic solutions coexist:
// 10^4 random starts, every unknown coefficient (x's: v = x' is condensed)
// uniform in [-2, 2], solved by RHB and
// HDHB at the same order, with the wall time of the whole census. The
// "error" columns are what makes a row trustworthy: the largest relative
// distance of a physical cluster to its alias-free reference solve, and the
// largest difference between Hill's and the CVODE monodromy's multipliers.
//
//   build/tests/benchmarks/montecarlo_benchmark [starts=10000] [order=3] [threads=0] [seed=1] [solver=auto]
// (solver: auto, newton, lm, tikhonov; the census with another solver, as
// the README's "tried and not kept" measured).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "examples/example_system.h"
#include "integrators/floquet.h"
#include "rmhb/monte_carlo.h"

int main(int argc, char** argv) {
  using namespace rmhb;
  const long starts = argc > 1 ? std::atol(argv[1]) : 10000;
  const int order = argc > 2 ? std::atoi(argv[2]) : 3;
  const int threads = argc > 3 ? std::atoi(argv[3]) : 0;
  const unsigned long seed = argc > 4 ? std::strtoul(argv[4], nullptr, 10) : 1;
  const examples::ExampleSetup e = examples::BuildExample("duffing", {{"w", 2.0}});

  MonteCarloOptions options;
  options.starts = starts;
  options.solve.order = order;
  options.threads = threads;
  options.seed = seed;
  if (argc > 5) options.solve.solver.method = ParseSolverMethod(argv[5]);
  const integrators::OdeSystem ode{2, e.original.rhs};
  options.original_check = [&](const HarmonicSolution& s) {
    const integrators::FloquetReport f =
        integrators::FloquetMultipliers(ode, e.original.state(s, 0.0), 0.0, 2 * M_PI / s.frequencies()[0]);
    return OriginalCheck{f.ok, f.stable, f.multipliers, f.closure_error, f.message};
  };
  const MonteCarloSummary summary = RunMonteCarlo(e.problem, options);

  std::printf("Duffing x'' + 0.1 x' + x + x^3 = cos(2 t): %ld starts, x's coefficients uniform in [-2, 2], "
              "seed %lu, order %d, %d threads\n\n",
              starts, seed, order, summary.threads);
  std::printf("| method | M | upper %% | lower %% | unstable %% | non-physical %% | distinct (non-physical) | failed starts | max distance (physical) | max Hill-Floquet |mu| diff | solve CPU s |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const RuleCensus& r : summary.rules) {
    // Upper and lower: the stable physical clusters by amplitude.
    double upper = 0, lower = 0, upper_amplitude = -1, distance = 0, multiplier_error = 0;
    for (const SolutionCluster& c : r.clusters) {
      if (c.solution_class == SolutionClass::kNonPhysical) continue;
      distance = std::max(distance, c.reference_distance);
      if (c.hill && c.original && c.original->ok)
        for (const auto& mu : c.hill->multipliers) {
          double nearest = HUGE_VAL;
          for (const auto& nu : c.original->multipliers) nearest = std::min(nearest, std::abs(mu - nu));
          multiplier_error = std::max(multiplier_error, nearest);
        }
      if (c.solution_class == SolutionClass::kPhysicalStable) upper_amplitude = std::max(upper_amplitude, c.amplitude);
    }
    for (const SolutionCluster& c : r.clusters)
      if (c.solution_class == SolutionClass::kPhysicalStable)
        (c.amplitude == upper_amplitude ? upper : lower) += c.share;
    std::printf("| %s | %d%s | %.2f | %.2f | %.2f | %.2f | %zu (%d) | %ld | %.1e | %.1e | %.2f |\n",
                ToString(r.rule), r.samples, r.samples >= r.alias_free_samples ? "" : " (aliased)",
                upper, lower, r.share(SolutionClass::kPhysicalUnstable),
                r.share(SolutionClass::kNonPhysical), r.clusters.size(), r.non_physical_clusters(),
                r.failed, distance, multiplier_error, r.solve_seconds);
  }
  std::printf("\npaper (Table 1): RHB 57.13 / 19.71 / 23.16 / 0 %%; HDHB 29.14 / 14.21 / 15.96 / 48.69 %%, "
              "58 distinct (55 non-physical)\n");
  std::printf("wall time %.2f s (solves, clustering, %d reference solves, Hill and Floquet)\n\n%s",
              summary.seconds, [&] {
                int n = 0;
                for (const auto& r : summary.rules) n += static_cast<int>(r.clusters.size());
                return n;
              }(),
              summary.FullReport().c_str());
  return 0;
}

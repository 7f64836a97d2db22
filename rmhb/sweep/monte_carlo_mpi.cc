#include "rmhb/sweep/monte_carlo_mpi.h"

#include <chrono>

#include "rmhb/sweep/mpi.h"

namespace rmhb::sweep {
namespace {

// A start's outcome as numbers for MPI: converged flag, coefficients
// (row-major), frequencies; the same length for every start.
void PackOutcome(const StartOutcome& o, int coefficients, int bases, std::vector<double>* out) {
  const bool converged = o.coefficients.size() > 0;
  out->push_back(converged);
  for (int i = 0; i < coefficients; ++i)
    out->push_back(converged ? o.coefficients(i / o.coefficients.cols(), i % o.coefficients.cols()) : 0.0);
  for (int b = 0; b < bases; ++b) out->push_back(converged ? o.frequencies[b] : 0.0);
}

}  // namespace

MonteCarloSummary DistributedMonteCarlo(const HarmonicBalanceProblem& problem, const MonteCarloOptions& options,
                                        int rank, int ranks) {
  if (ranks == 1) return RunMonteCarlo(problem, options);
  const auto begin = std::chrono::steady_clock::now();
  StartSolves solves = SolveStarts(problem, options, rank, ranks);
  const int rows = problem.system.num_variables(), cols = HarmonicBasis::Periodic(options.solve.order).num_coefficients();
  const int bases = static_cast<int>(problem.frequencies.size()), record = 1 + rows * cols + bases;
  std::vector<double> mine;
  for (const auto& rule : solves.outcomes)
    for (long i = rank; i < options.starts; i += ranks) PackOutcome(rule[i], rows * cols, bases, &mine);
  const std::vector<double> all = GatherToRoot(mine);
  for (double& s : solves.rule_seconds) s = SumToRoot(s);
  if (rank != 0) return {};
  const double* p = all.data();
  for (int r = 0; r < ranks; ++r)
    for (auto& rule : solves.outcomes)
      for (long i = r; i < options.starts; i += ranks, p += record) {
        if (p[0] == 0) continue;
        rule[i].coefficients = Eigen::Map<const Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(p + 1, rows, cols);
        rule[i].frequencies.assign(p + 1 + rows * cols, p + record);
      }
  MonteCarloSummary summary = CensusOfStarts(problem, options, solves);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return summary;
}

}  // namespace rmhb::sweep

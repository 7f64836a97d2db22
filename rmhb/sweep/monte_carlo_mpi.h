#ifndef RMHB_SWEEP_MONTE_CARLO_MPI_H_
#define RMHB_SWEEP_MONTE_CARLO_MPI_H_

// A Monte Carlo census (rmhb/monte_carlo.h) over MPI ranks: rank r solves
// starts r, r + ranks, ... (each on its threads); rank 0 gathers every
// outcome and classifies. The census is the one a single process finds (it
// depends on the outcomes by start index only); the other ranks get an
// empty summary. Every rank calls it; with one rank it is RunMonteCarlo.
// As a runner of rmhb::Census (rmhb/pipeline/census.h):
//   Census(model, options, [&](const auto& p, const auto& o) { return DistributedMonteCarlo(p, o, rank, ranks); });

#include "rmhb/monte_carlo.h"

namespace rmhb::sweep {

MonteCarloSummary DistributedMonteCarlo(const HarmonicBalanceProblem& problem, const MonteCarloOptions& options,
                                        int rank, int ranks);

}  // namespace rmhb::sweep

#endif  // RMHB_SWEEP_MONTE_CARLO_MPI_H_

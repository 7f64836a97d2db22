#ifndef RMHB_SWEEP_MPI_H_
#define RMHB_SWEEP_MPI_H_

// MPI for sweeps and Monte Carlo censuses. A sweep's lines over MPI (OpenMPI's mpirun, or srun): rank 0 hands out
// lines one at a time to whichever rank asks (dynamic load balancing: a
// line near a resonance can cost orders of magnitude more than one away
// from it); the other ranks solve them. With one rank, that rank solves
// every line itself. Results travel through the journal on the shared file
// system, not through MPI (rmhb/sweep/journal.h), so a rank killed mid-line
// loses only its current point.
//
// Rank 0 polls for requests with MPI_Iprobe and a short sleep instead of a
// blocking receive, which OpenMPI implements as a busy wait: on an
// oversubscribed node a spinning dispatcher would steal a core from a worker.

#include <vector>

#include "rmhb/sweep/run.h"

namespace rmhb::sweep {

// MPI_Init on construction, MPI_Finalize on destruction, when the process
// was started by a launcher (mpirun, mpiexec, srun); without one it is
// rank 0 of 1 and MPI is not initialised (a singleton start-up costs time).
class MpiSession {
 public:
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  int rank_ = 0, size_ = 1;
};

// Rank 0: serve `lines` to ranks 1..size-1 until each has been told there
// is no more (returns then). With size 1: not used.
void ServeLines(const std::vector<long>& lines, int size);
// Ranks > 0: the source that asks rank 0 for the next line.
LineSource RequestLines();

// Collective helpers (every rank calls them; rank 0 gets the result).
// GatherToRoot: every rank's vector, concatenated in rank order.
std::vector<double> GatherToRoot(const std::vector<double>& local);
double SumToRoot(double value);
long SumToRoot(long value);
double MaxToRoot(double value);
void Barrier();
[[noreturn]] void AbortAll(int exit_code);  // MPI_Abort, e.g. after an error on one rank

// True between MpiSession's construction and destruction.
bool MpiActive();

}  // namespace rmhb::sweep

#endif  // RMHB_SWEEP_MPI_H_

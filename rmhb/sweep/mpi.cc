#include "rmhb/sweep/mpi.h"

#include <mpi.h>

#include <chrono>
#include <cstdlib>
#include <thread>

namespace rmhb::sweep {
namespace {

constexpr int kRequestTag = 1, kLineTag = 2;
bool active = false;

}  // namespace

// Started by mpirun/mpiexec or srun: the launchers' environment says so.
bool Launched() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

MpiSession::MpiSession(int* argc, char*** argv) {
  // A singleton MPI_Init costs OpenMPI ~0.4 s of start-up (it sets up a
  // runtime for one process): a run without a launcher is one rank anyway.
  if (!Launched()) return;
  MPI_Init(argc, argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  active = true;
}

MpiSession::~MpiSession() {
  if (!active) return;
  active = false;
  MPI_Finalize();
}

bool MpiActive() { return active; }

void ServeLines(const std::vector<long>& lines, int size) {
  std::size_t next = 0;
  for (int working = size - 1; working > 0;) {
    int waiting = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, kRequestTag, MPI_COMM_WORLD, &waiting, &status);
    if (!waiting) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    int request = 0;
    MPI_Recv(&request, 1, MPI_INT, status.MPI_SOURCE, kRequestTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    long line = next < lines.size() ? lines[next++] : -1;
    if (line < 0) --working;
    MPI_Send(&line, 1, MPI_LONG, status.MPI_SOURCE, kLineTag, MPI_COMM_WORLD);
  }
}

LineSource RequestLines() {
  return [] {
    int request = 1;
    long line = -1;
    MPI_Send(&request, 1, MPI_INT, 0, kRequestTag, MPI_COMM_WORLD);
    MPI_Recv(&line, 1, MPI_LONG, 0, kLineTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return line;
  };
}

std::vector<double> GatherToRoot(const std::vector<double>& local) {
  if (!active) return local;
  int size = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const int count = static_cast<int>(local.size());
  std::vector<int> counts(size), offsets(size);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  long total = 0;
  for (int r = 0; r < size; ++r) offsets[r] = static_cast<int>(total), total += counts[r];
  std::vector<double> all(rank == 0 ? total : 0);
  MPI_Gatherv(local.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0,
              MPI_COMM_WORLD);
  return all;
}

double SumToRoot(double value) {
  double sum = value;
  if (active) MPI_Reduce(&value, &sum, 1, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  return sum;
}

long SumToRoot(long value) {
  long sum = value;
  if (active) MPI_Reduce(&value, &sum, 1, MPI_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
  return sum;
}

double MaxToRoot(double value) {
  double max = value;
  if (active) MPI_Reduce(&value, &max, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  return max;
}

void Barrier() {
  if (active) MPI_Barrier(MPI_COMM_WORLD);
}

void AbortAll(int exit_code) {
  if (active) MPI_Abort(MPI_COMM_WORLD, exit_code);
  std::exit(exit_code);
}

}  // namespace rmhb::sweep

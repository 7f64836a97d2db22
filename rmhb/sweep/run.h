#ifndef RMHB_SWEEP_RUN_H_
#define RMHB_SWEEP_RUN_H_

// A sweep as work: lines of the grid (rmhb/sweep/parameter_grid.h) handed
// out one at a time by a LineSource -- a counter in one process, a
// dispatcher over MPI (rmhb/sweep/mpi.h) -- each solved point by point
// in order and journaled (rmhb/sweep/journal.h). Points already in the
// journal are not solved again; the last of them seeds the continuation of
// the next, read back bit for bit. So the points' results, and the file made
// from them, do not depend on which process solved a line, on how many there
// were, or on where an earlier run was killed.

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rmhb/sweep/journal.h"
#include "rmhb/sweep/sweep.h"

namespace rmhb::sweep {

// The next line to solve, or -1 when there is none left.
using LineSource = std::function<long()>;

// The lines that have a point missing from `done`, in order.
std::vector<long> LinesToDo(const ParameterGrid& grid, const std::map<long, nlohmann::json>& done);

struct RunStats {
  long solved = 0;   // points solved by this process
  long resumed = 0;  // points of its lines read from the journal
  double seconds = 0;
};

// Solves the lines `next` gives until it returns -1. `on_point` (optional)
// sees every point this process solves, e.g. for a log line.
RunStats RunLines(const SweepModel& model, const ParameterGrid& grid, const SweepOptions& options,
                  const LineSource& next, const std::map<long, nlohmann::json>& done, JournalWriter* journal,
                  const std::function<void(const PointResult&)>& on_point = {});

// Every point of the grid from the journal, by index. Throws
// std::runtime_error naming the first missing point.
std::vector<nlohmann::json> CollectPoints(const ParameterGrid& grid, const JournalContents& contents);

}  // namespace rmhb::sweep

#endif  // RMHB_SWEEP_RUN_H_

#ifndef RMHB_SWEEP_GRID_SWEEP_H_
#define RMHB_SWEEP_GRID_SWEEP_H_

// A model swept over a parameter grid, on one process or many, into one
// HDF5 file (rmhb sweep):
//   GridSweepSummary s = SweepGrid(model, guess, grid, options, rank, ranks);
// Every rank calls it (rank 0 of 1 without MPI). The lines of the grid are
// solved point by point (rmhb/sweep/run.h; over MPI rank 0 hands them out,
// rmhb/sweep/mpi.h) and journaled in OUT.journal/ (rmhb/sweep/journal.h);
// rank 0 then writes OUT (rmhb/sweep/sweep_file.h) through OUT.partial and
// removes the journal. An interrupted sweep finishes with `resume`: points
// already journaled are not solved again, so the file does not depend on
// where it was interrupted nor on the number of ranks. A point that fails is
// recorded in the file; misuse (invalid options, a journal left by another
// sweep or left without `resume`) throws std::invalid_argument.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rmhb/pipeline/model.h"
#include "rmhb/sweep/parameter_grid.h"
#include "rmhb/sweep/sweep.h"
#include "rmhb/sweep/sweep_file.h"

namespace rmhb::sweep {

struct GridSweepOptions {
  SweepOptions sweep;  // the solve options, random starts, seed, stability
  std::string out = "sweep.h5";
  bool resume = false;        // finish an interrupted sweep from OUT.journal/
  bool keep_journal = false;  // keep OUT.journal/ after the file is written
  std::string log;            // append one line per computed point to this file (empty: none)
  // What identifies the sweep (software, model, model_text, parameters, the
  // options that change results): its fingerprint ties a journal to it.
  // fingerprint and variables are filled by SweepGrid.
  SweepFileInfo info;
  std::string IsValid() const;
};

struct GridSweepSummary {
  std::string model, out;
  std::vector<GridAxis> axes;
  long points = 0, lines = 0;
  long computed = 0, resumed = 0, duplicates = 0, torn_lines = 0;  // of the journal
  long solved = 0, no_solution = 0, failed = 0, solutions = 0;     // of the points
  int ranks = 1;
  double seconds = 0, peak_memory_mib = 0;  // the largest of any rank
  std::vector<nlohmann::json> point_records;  // every point's record, in index order
  std::string FullReport() const;
  nlohmann::json ToJson() const;  // `rmhb sweep --json`
};

// Rank 0 gets the summary; the other ranks an empty one once their lines are done.
GridSweepSummary SweepGrid(const Model& model, const HarmonicSolution& guess, const ParameterGrid& grid,
                           const GridSweepOptions& options, int rank, int ranks);

// The parameter values of a grid point, by axis name.
std::map<std::string, double> AtValues(const ParameterGrid& grid, const std::vector<double>& values);

}  // namespace rmhb::sweep

#endif  // RMHB_SWEEP_GRID_SWEEP_H_

#ifndef RMHB_SWEEP_SWEEP_FILE_H_
#define RMHB_SWEEP_SWEEP_FILE_H_

// The result of a sweep as one HDF5 file (read by h5py, MATLAB, Julia,
// ParaView, h5dump):
//   /                root attributes: format, software, model, model_text
//                    (a model file's content), parameters, grid, options
//                    (JSON), fingerprint
//   /grid/NAME       each axis' values
//   /points/...      per point, in index order (first axis fastest): values
//                    [points x axes], status, message, solutions (count),
//                    first_solution (row in /solutions), solves, non_physical
//   /solutions/...   per solution, grouped by point: point, frequencies
//                    [solutions x bases], amplitude, residual, stability,
//                    max_real_part, route, coefficients [solutions x
//                    variables x 2K-1] (attribute "variables": their names)
//   /map/amplitude   largest amplitude per point (NaN where none) and
//   /map/count       number of solutions, both shaped [n_last ... n_first]
// Nothing in it depends on when or by how many processes it was computed:
// no timestamps (object time tracking off), no run times; the same sweep
// gives the same bytes.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rmhb/sweep/parameter_grid.h"

namespace rmhb::sweep {

struct SweepFileInfo {
  std::string software;     // "rmhb 0.1.0"
  std::string model;        // as given on the command line
  std::string model_text;   // the model file's content, empty for a built-in example
  std::string parameters;   // the --set values
  std::string options;      // JSON of the options that change results
  std::string fingerprint;
  std::vector<std::string> variables;  // names, for the coefficients
};

// `points`: every grid point's journal record (rmhb/sweep/journal.h), in
// index order. Throws std::runtime_error naming the path on an HDF5 error.
void WriteSweepFile(const std::string& path, const ParameterGrid& grid, const SweepFileInfo& info,
                    const std::vector<nlohmann::json>& points);

}  // namespace rmhb::sweep

#endif  // RMHB_SWEEP_SWEEP_FILE_H_

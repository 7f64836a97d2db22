#ifndef RMHB_PLOT_BRANCH_PLOT_H_
#define RMHB_PLOT_BRANCH_PLOT_H_

// The frequency-response picture of `solve --continue ... --plot FILE`: a
// value of each point (the amplitude max|x(t)| of a variable, or the first
// base frequency) against the parameter; stable parts solid, unstable
// dashed, neutral or unknown dotted; folds, branch points (BP), period
// doublings (PD) and Neimark-Sacker points (NS) marked and labelled; the
// period-2T branches of --switch-branches drawn alongside. The data drawn go
// to FILE.dat as well (parameter, value, stability, fold, mark, branch), so
// a script or a test can read exactly what the figure shows.

#include <string>
#include <vector>

#include "rmhb/continuation.h"

namespace rmhb::plot {

struct BranchRow {
  double parameter = 0, value = 0;
  std::string stability;  // stable, unstable, neutral, unknown
  bool fold = false;
  std::string mark = "-";  // fold, BP, PD, NS, or "-"
  int branch = 0;          // 0: the branch traced; k: the k-th period-2T (or locked) branch
  std::string family = "period 2T";  // what branch k > 0 is, for the legend
};

// What is plotted of a point: "frequency", "ratio" (w2/w1 of a torus: the
// devil's staircase) or a variable's name (its amplitude). Throws
// std::invalid_argument naming the variables otherwise.
std::vector<BranchRow> BranchRows(const ContinuationSummary& summary, const std::string& plot_var, int branch = 0);

// A locked branch (rmhb/pipeline/branch.h TongueReport) on the staircase:
// every point at w2/w1 = `ratio` (p/q), with its stability and folds.
std::vector<BranchRow> LockedRows(const ContinuationSummary& locked, double ratio, int branch);

// FILE.dat: a header line, then one row per point.
void WriteBranchData(const std::vector<BranchRow>& rows, const std::string& parameter, const std::string& plot_var,
                     const std::string& file);
// The figure (PNG or SVG by extension); throws like WritePlot.
void PlotBranch(const std::vector<BranchRow>& rows, const std::string& title, const std::string& parameter,
                const std::string& plot_var, const std::string& file);

}  // namespace rmhb::plot

#endif  // RMHB_PLOT_BRANCH_PLOT_H_

#ifndef RMHB_SWEEP_PARAMETER_GRID_H_
#define RMHB_SWEEP_PARAMETER_GRID_H_

// The points of a parameter sweep: a tensor grid over one or more model
// parameters, each axis NAME=a:b:n (n equally spaced values from a to b).
// Point index = i0 + n0 (i1 + n1 (i2 + ...)): the first axis runs fastest.
// A "line" is the n0 points that differ only in the first axis; a sweep
// solves a line in order, each point continued from the one before, so a
// line is the unit of work that goes to one process (rmhb/sweep/run.h).

#include <string>
#include <vector>

namespace rmhb::sweep {

struct GridAxis {
  std::string name;
  double from = 0, to = 0;
  int count = 1;
  double Value(int i) const;  // from + i (to - from) / (count - 1); `from` when count = 1
};

// "NAME=a:b:n" -> axis; throws std::invalid_argument quoting the text and
// saying what is wrong (no name, not three fields, n < 1, a non-finite bound).
GridAxis ParseGridAxis(const std::string& text);

class ParameterGrid {
 public:
  // Throws std::invalid_argument for no axes, a name given twice, or more
  // than max_points points.
  explicit ParameterGrid(std::vector<GridAxis> axes, long max_points = 100'000'000);

  const std::vector<GridAxis>& axes() const { return axes_; }
  long size() const { return size_; }
  long num_lines() const { return size_ / line_length(); }
  int line_length() const { return axes_[0].count; }
  long LineOf(long point) const { return point / line_length(); }
  long FirstPointOf(long line) const { return line * line_length(); }
  // Per axis: the value index of `point`, and the parameter values.
  std::vector<int> Indices(long point) const;
  std::vector<double> Values(long point) const;

 private:
  std::vector<GridAxis> axes_;
  long size_ = 1;
};

}  // namespace rmhb::sweep

#endif  // RMHB_SWEEP_PARAMETER_GRID_H_

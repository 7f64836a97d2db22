// Sampled solution of an initial value problem.

#ifndef RMHB_INTEGRATORS_TRAJECTORY_H_
#define RMHB_INTEGRATORS_TRAJECTORY_H_

#include <Eigen/Core>
#include <vector>

namespace rmhb::integrators {

struct Trajectory {
  std::vector<double> times;
  // Row k is the state at times[k]; columns are the state components. Rows
  // rather than columns so that one component over time is a contiguous
  // column, which is what spectral post-processing (FFT, harmonic fits) wants.
  Eigen::MatrixXd states;

  int size() const { return static_cast<int>(times.size()); }
  int dimension() const { return static_cast<int>(states.cols()); }

  // Time history of one state component. Throws std::out_of_range.
  Eigen::VectorXd Component(int index) const;
};

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_TRAJECTORY_H_

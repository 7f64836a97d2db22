#include "integrators/trajectory.h"

#include <stdexcept>
#include <string>

namespace rmhb::integrators {

Eigen::VectorXd Trajectory::Component(int index) const {
  if (index < 0 || index >= states.cols()) {
    throw std::out_of_range("Trajectory::Component: index " + std::to_string(index) +
                            " outside [0, " + std::to_string(states.cols()) + ")");
  }
  return states.col(index);
}

}  // namespace rmhb::integrators

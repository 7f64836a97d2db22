#include "frequency_id/window.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "frequency_id/sample_grid.h"

namespace rmhb::frequency_id {
namespace {

// The mean of (1 - cos x)^q over a period is binom(2q, q) / 2^q.
double HannPowerMean(int order) {
  double binomial = 1.0;
  for (int k = 1; k <= order; ++k) binomial = binomial * (order + k) / k;
  return binomial / std::ldexp(1.0, order);
}

}  // namespace

Window::Window(int order) : order_(order) {
  if (order < 1) throw std::invalid_argument("Window: order must be >= 1");
  scale_ = 1.0 / HannPowerMean(order);
}

double Window::operator()(double s) const {
  return scale_ * std::pow(1.0 - std::cos(2.0 * kPi * s), order_);
}

Eigen::VectorXd Window::Sample(int size) const {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(size);
  if (size < 3) return w;
  // Mirrored so the sampled window is exactly symmetric about the centre.
  for (int n = 1; n < size - 1; ++n) {
    const int m = std::min(n, size - 1 - n);
    w(n) = (*this)(static_cast<double>(m) / (size - 1));
  }
  return w;
}

int Window::ChooseOrder(double min_spacing_bins, double lobe_separation, int max_order) {
  max_order = std::max(1, max_order);
  if (!(min_spacing_bins > 0.0) || !(lobe_separation > 0.0)) return 1;
  const double q = std::floor(min_spacing_bins / lobe_separation) - 1.0;
  if (!(q >= 1.0)) return 1;
  return q >= max_order ? max_order : static_cast<int>(q);
}

}  // namespace rmhb::frequency_id

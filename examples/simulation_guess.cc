#include "examples/simulation_guess.h"

#include <cmath>
#include <stdexcept>

#include "rmhb/sampling.h"
#include "rmhb/spectral_transform.h"

namespace rmhb::examples {
namespace {

void Rk4(const std::function<void(double, const double*, double*)>& f, double t, double h,
         Eigen::VectorXd* y) {
  const int n = static_cast<int>(y->size());
  Eigen::VectorXd k1(n), k2(n), k3(n), k4(n), tmp(n);
  f(t, y->data(), k1.data());
  tmp = *y + 0.5 * h * k1;
  f(t + 0.5 * h, tmp.data(), k2.data());
  tmp = *y + 0.5 * h * k2;
  f(t + 0.5 * h, tmp.data(), k3.data());
  tmp = *y + h * k3;
  f(t + h, tmp.data(), k4.data());
  *y += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
}

}  // namespace

HarmonicSolution GuessFromSimulation(
    const std::function<void(double, const double*, double*)>& rhs, Eigen::VectorXd y,
    double period_guess, int transient_periods, const HarmonicBasis& basis,
    const std::vector<Variable>& variables,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& aux) {
  // A stiff relaxation (Van der Pol, eps = 50) makes the explicit step
  // unstable at 4000 steps per period: the state blows up. Refine until the
  // run stays finite and finds the maxima.
  const Eigen::VectorXd y0 = y;
  std::vector<double> maxima;
  std::vector<Eigen::VectorXd> states;
  for (int steps = 4000; steps <= 256000 && maxima.size() < 2; steps *= 4) {
    y = y0;
    maxima.clear();
    states.clear();
    const double h = period_guess / steps;
    double t = 0;
    for (int i = 0; i < steps * transient_periods && y.allFinite(); ++i, t += h) Rk4(rhs, t, h, &y);
    // Two successive maxima of y[0]: y[0]' changes sign from + to -.
    const int n = static_cast<int>(y.size());
    Eigen::VectorXd d(n);
    rhs(t, y.data(), d.data());
    double prev_slope = d(0);
    for (int i = 0; i < steps * 4 && maxima.size() < 2 && y.allFinite(); ++i, t += h) {
      Rk4(rhs, t, h, &y);
      rhs(t + h, y.data(), d.data());
      if (prev_slope > 0 && d(0) <= 0) {
        maxima.push_back(t + h * prev_slope / (prev_slope - d(0)));
        states.push_back(y);
      }
      prev_slope = d(0);
    }
    if (!y.allFinite()) maxima.clear();
  }
  if (maxima.size() < 2) throw std::runtime_error("GuessFromSimulation: no periodic motion found");
  const double period = maxima[1] - maxima[0];
  // One period from the second maximum, sampled uniformly.
  const int samples = FftFriendlySize(std::max(4 * basis.size() + 8, 1024));
  const int sub = 8;
  const double step = period / (samples * sub);
  Eigen::VectorXd z = states[1];
  Eigen::MatrixXd values(samples, variables.size());
  double tau = 0;
  for (int s = 0; s < samples; ++s) {
    values.row(s) = aux(z).transpose();
    for (int k = 0; k < sub; ++k, tau += step) Rk4(rhs, tau, step, &z);
  }
  SpectralTransform transform(basis, Sampling::Uniform(samples));
  Eigen::MatrixXd coefficients(variables.size(), basis.num_coefficients());
  Eigen::VectorXd column(samples), row(basis.num_coefficients());
  for (size_t j = 0; j < variables.size(); ++j) {
    column = values.col(j);
    transform.Project(column.data(), row.data());
    coefficients.row(j) = row.transpose();
  }
  return HarmonicSolution(basis, {2 * M_PI / period}, coefficients, variables);
}

}  // namespace rmhb::examples

#include "rmhb/harmonic_solution.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <map>
#include <stdexcept>
#include <vector>

#include "rmhb/spectral_transform.h"

namespace rmhb {

HarmonicSolution::HarmonicSolution(HarmonicBasis basis, std::vector<double> frequencies,
                                   Eigen::MatrixXd coefficients, std::vector<Variable> variables)
    : basis_(std::move(basis)),
      frequencies_(std::move(frequencies)),
      coefficients_(std::move(coefficients)),
      variables_(std::move(variables)) {
  if (static_cast<int>(frequencies_.size()) != basis_.num_bases())
    throw std::invalid_argument("HarmonicSolution: one frequency per base expected");
  if (coefficients_.rows() != static_cast<long>(variables_.size()) ||
      coefficients_.cols() != basis_.num_coefficients())
    throw std::invalid_argument("HarmonicSolution: coefficient matrix has the wrong shape");
}

HarmonicSolution HarmonicSolution::FromAngles(
    const HarmonicBasis& basis, std::vector<double> frequencies, std::vector<Variable> variables,
    const std::function<Eigen::VectorXd(const std::vector<double>&)>& f) {
  const int d = basis.num_bases();
  std::vector<int> grid(d);
  for (int b = 0; b < d; ++b) grid[b] = FftFriendlySize(4 * basis.Reach(b) + 8);
  Sampling sampling = d == 1 ? Sampling::Uniform(grid[0]) : Sampling::Torus(grid);
  SpectralTransform transform(basis, sampling);
  const long M = sampling.total();
  const int n = static_cast<int>(variables.size());
  Eigen::MatrixXd samples(M, n);
  std::vector<double> theta(d);
  for (long s = 0; s < M; ++s) {
    long r = s;
    for (int b = d - 1; b >= 0; --b) {
      theta[b] = 2.0 * M_PI * double(r % grid[b]) / grid[b];
      r /= grid[b];
    }
    Eigen::VectorXd v = f(theta);
    if (v.size() != n) throw std::invalid_argument("HarmonicSolution::FromAngles: wrong size");
    samples.row(s) = v.transpose();
  }
  Eigen::MatrixXd coefficients(n, basis.num_coefficients());
  Eigen::VectorXd column(M), row(basis.num_coefficients());
  for (int j = 0; j < n; ++j) {
    column = samples.col(j);
    transform.Project(column.data(), row.data());
    coefficients.row(j) = row.transpose();
  }
  return HarmonicSolution(basis, std::move(frequencies), std::move(coefficients),
                          std::move(variables));
}

int HarmonicSolution::IndexOf(const std::string& name) const {
  for (int j = 0; j < num_variables(); ++j)
    if (variables_[j].name == name) return j;
  return -1;
}

double HarmonicSolution::Value(int j, double t) const {
  double v = coefficients_(j, 0);
  for (int k = 1; k < basis_.size(); ++k) {
    const double a = basis_.Frequency(k, frequencies_) * t;
    v += coefficients_(j, 2 * k - 1) * std::cos(a) + coefficients_(j, 2 * k) * std::sin(a);
  }
  return v;
}

double HarmonicSolution::Derivative(int j, double t) const {
  double v = 0;
  for (int k = 1; k < basis_.size(); ++k) {
    const double w = basis_.Frequency(k, frequencies_);
    v += w * (-coefficients_(j, 2 * k - 1) * std::sin(w * t) + coefficients_(j, 2 * k) * std::cos(w * t));
  }
  return v;
}

double HarmonicSolution::Amplitude(int j) const {
  const double period = 2 * M_PI / frequencies_[0];
  const int n = 64 * basis_.size();
  double best = 0, tbest = 0;
  // The scan only brackets the extremum for the polish below: on one base,
  // harmonic k's phase at sample i is e^{i k theta_i} by complex products
  // (a sin/cos pair per sample instead of one per harmonic and sample).
  const bool one_base = basis_.num_bases() == 1;
  int top = 0;
  for (int k = 1; one_base && k < basis_.size(); ++k) top = std::max(top, std::abs(basis_.harmonic(k)[0]));
  std::vector<std::complex<double>> power(top + 1);
  for (int i = 0; i < n; ++i) {
    const double t = period * i / n;
    double value = 0;
    if (one_base) {
      power[0] = 1;
      if (top > 0) power[1] = std::polar(1.0, frequencies_[0] * t);
      for (int m = 2; m <= top; ++m) power[m] = power[m - 1] * power[1];
      value = coefficients_(j, 0);
      for (int k = 1; k < basis_.size(); ++k) {
        const int m = basis_.harmonic(k)[0];
        const std::complex<double> phase = m >= 0 ? power[m] : std::conj(power[-m]);
        value += coefficients_(j, 2 * k - 1) * phase.real() + coefficients_(j, 2 * k) * phase.imag();
      }
    } else {
      value = Value(j, t);
    }
    if (std::abs(value) > best) best = std::abs(value), tbest = t;
  }
  // Polish the extremum with Newton on z'(t) = 0 (z'' by finite difference of z').
  double t = tbest;
  for (int it = 0; it < 20; ++it) {
    const double h = 1e-5 * period;
    const double d1 = Derivative(j, t);
    const double d2 = (Derivative(j, t + h) - Derivative(j, t - h)) / (2 * h);
    if (d2 == 0) break;
    const double step = d1 / d2;
    t -= step;
    if (std::abs(step) < 1e-15 * period) break;
  }
  return std::max(best, std::abs(Value(j, t)));
}

HarmonicSolution HarmonicSolution::OnBasis(const HarmonicBasis& basis) const {
  if (basis.num_bases() != basis_.num_bases())
    throw std::invalid_argument("HarmonicSolution::OnBasis: different number of bases");
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(num_variables(), basis.num_coefficients());
  c.col(0) = coefficients_.col(0);
  // Where each harmonic sits in this basis, looked up once: one base by
  // |k|, several through a map (HarmonicBasis::Find per harmonic is O(K)).
  std::vector<int> by_order;
  std::map<std::vector<int>, int> by_vector;
  if (basis_.num_bases() == 1) {
    by_order.assign(basis_.Reach(0) + 1, -1);
    for (int k = 0; k < basis_.size(); ++k) by_order[std::abs(basis_.harmonic(k)[0])] = k;
  } else {
    for (int k = 0; k < basis_.size(); ++k) by_vector.emplace(basis_.harmonic(k), k);
  }
  auto find = [&](const std::vector<int>& h) {
    if (basis_.num_bases() == 1) {
      const int order = std::abs(h[0]);
      return order < static_cast<int>(by_order.size()) ? by_order[order] : -1;
    }
    auto it = by_vector.find(h);
    if (it != by_vector.end()) return it->second;
    std::vector<int> neg(h);
    for (int& v : neg) v = -v;
    it = by_vector.find(neg);
    return it != by_vector.end() ? it->second : -1;
  };
  for (int k = 1; k < basis.size(); ++k) {
    const int from = find(basis.harmonic(k));
    if (from <= 0) continue;
    // Stored with the other sign: cos is even, sin odd.
    const double sign = basis_.harmonic(from) == basis.harmonic(k) ? 1.0 : -1.0;
    c.col(2 * k - 1) = coefficients_.col(2 * from - 1);
    c.col(2 * k) = sign * coefficients_.col(2 * from);
  }
  return HarmonicSolution(basis, frequencies_, std::move(c), variables_);
}

HarmonicSolution HarmonicSolution::Shifted(const std::vector<double>& phase) const {
  if (static_cast<int>(phase.size()) != basis_.num_bases())
    throw std::invalid_argument("HarmonicSolution::Shifted: one phase per base expected");
  // a cos(u + d) + b sin(u + d) = (a cos d + b sin d) cos u + (b cos d - a sin d) sin u.
  Eigen::MatrixXd c = coefficients_;
  for (int k = 1; k < basis_.size(); ++k) {
    double d = 0;
    for (int i = 0; i < basis_.num_bases(); ++i) d += basis_.harmonic(k)[i] * phase[i];
    const double cd = std::cos(d), sd = std::sin(d);
    c.col(2 * k - 1) = cd * coefficients_.col(2 * k - 1) + sd * coefficients_.col(2 * k);
    c.col(2 * k) = cd * coefficients_.col(2 * k) - sd * coefficients_.col(2 * k - 1);
  }
  return HarmonicSolution(basis_, frequencies_, std::move(c), variables_);
}

HarmonicSolution HarmonicSolution::WithFrequencies(std::vector<double> frequencies) const {
  return HarmonicSolution(basis_, std::move(frequencies), coefficients_, variables_);
}

HarmonicSolution HarmonicSolution::OnMultipleFrequency(int g) const {
  if (basis_.num_bases() != 1 || g < 1)
    throw std::invalid_argument("OnMultipleFrequency: one base and g >= 1 only");
  const HarmonicBasis basis = HarmonicBasis::Periodic(std::max(1, basis_.order() / g));
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(num_variables(), basis.num_coefficients());
  c.col(0) = coefficients_.col(0);
  for (int k = 1; k < basis.size(); ++k) {
    const int from = basis_.Find({g * basis.harmonic(k)[0]});
    if (from < 1) continue;
    c.col(2 * k - 1) = coefficients_.col(2 * from - 1);
    c.col(2 * k) = coefficients_.col(2 * from);
  }
  return HarmonicSolution(basis, {g * frequencies_[0]}, std::move(c), variables_);
}

}  // namespace rmhb

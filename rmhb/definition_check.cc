#include "rmhb/definition_check.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "rmhb/sampling.h"

namespace rmhb {

std::string DefinitionCheckOptions::IsValid() const {
  if (oversampling < 2) return "oversampling must be >= 2 (the grid must fall between the samples)";
  if (!(floor > 0) || !(ceiling >= floor) || !std::isfinite(ceiling))
    return "need 0 < floor <= ceiling < inf";
  if (!(truncation_factor >= 0) || !std::isfinite(truncation_factor))
    return "truncation_factor must be finite and >= 0";
  return "";
}

std::string DefinitionCheck::Report() const {
  std::ostringstream out;
  out.precision(3);
  out << "max |solved - definition| " << error;
  if (!worst_variable.empty()) {
    out << " (relative) in " << worst_variable << " at ";
    if (std::isfinite(worst_time)) {
      out << "t = " << worst_time;
    } else {
      out << "angles";
      for (double a : worst_angles) out << " " << a;
    }
  }
  out << (physical ? " <= " : " > ") << "tolerance " << tolerance << " on " << points
      << " points between the samples";
  return out.str();
}

HarmonicSolution TimeDerivative(const HarmonicSolution& solution, int times) {
  Eigen::MatrixXd c = solution.coefficients();
  const HarmonicBasis& basis = solution.basis();
  for (int n = 0; n < times; ++n) {
    c.col(0).setZero();
    for (int k = 1; k < basis.size(); ++k) {
      const double rate = basis.Frequency(k, solution.frequencies());
      const Eigen::VectorXd a = c.col(2 * k - 1);
      c.col(2 * k - 1) = rate * c.col(2 * k);
      c.col(2 * k) = -rate * a;
    }
  }
  return HarmonicSolution(basis, solution.frequencies(), std::move(c), solution.variables());
}

DefinitionCheck CheckDefinitions(const HarmonicSolution& solution,
                                 const VariableDefinitions& definitions,
                                 const std::vector<int>& collocation_samples,
                                 const DefinitionCheckOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (std::string why = options.IsValid(); !why.empty())
    throw std::invalid_argument("CheckDefinitions: " + why);
  if (!definitions) throw std::invalid_argument("CheckDefinitions: no definitions given");
  const HarmonicBasis& basis = solution.basis();
  const int d = basis.num_bases(), n = solution.num_variables(), K = basis.size();

  // The grid: per base, oversampling x the collocation samples (at least the
  // basis's own resolution), shifted by half a step off every sample.
  std::vector<int> grid(d);
  long total = 1;
  for (int b = 0; b < d; ++b) {
    const int m = collocation_samples.size() == static_cast<size_t>(d) ? collocation_samples[b] : 0;
    grid[b] = FftFriendlySize(options.oversampling * std::max(m, 2 * basis.Reach(b) + 1));
    total *= grid[b];
  }

  std::vector<Eigen::MatrixXd> coefficients;  // [derivative] variables x coefficients
  for (int j = 0; j <= definitions.derivatives; ++j)
    coefficients.push_back(TimeDerivative(solution, j).coefficients());

  int max_level = 0;
  std::vector<int> level(K, 0);
  for (int k = 0; k < K; ++k) {
    for (int v : basis.harmonic(k)) level[k] += std::abs(v);
    max_level = std::max(max_level, level[k]);
  }

  DefinitionCheck check;
  check.points = total;
  Eigen::VectorXd scale = Eigen::VectorXd::Zero(n), worst = Eigen::VectorXd::Zero(n);
  std::vector<std::vector<double>> worst_at(n, std::vector<double>(d, 0.0));
  // Blocks of points: the synthesis E (points x coefficients) times the
  // coefficients is one matrix product per block, with E kept small.
  const long block = 256;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> E(block, 2 * K - 1);
  std::vector<std::vector<double>> angles(block, std::vector<double>(d));
  std::vector<Eigen::VectorXd> z(coefficients.size());
  std::vector<Eigen::MatrixXd> values(coefficients.size());
  // theta_g = pi (2g + 1) / G, so exp(i m theta_g) is the (m (2g + 1) mod 2G)-th
  // of the 2G roots of unity: one table of 2G per base, exact, and no sin or
  // cos per harmonic and point.
  std::vector<std::vector<std::complex<double>>> roots(d);
  for (int b = 0; b < d; ++b)
    for (int j = 0; j < 2 * grid[b]; ++j) roots[b].push_back(std::polar(1.0, M_PI * j / grid[b]));
  std::vector<int> index(d);
  for (long first = 0; first < total; first += block) {
    const long count = std::min(block, total - first);
    for (long i = 0; i < count; ++i) {
      long r = first + i;
      for (int b = d - 1; b >= 0; --b) {
        index[b] = static_cast<int>(r % grid[b]);
        angles[i][b] = 2.0 * M_PI * (index[b] + 0.5) / grid[b];
        r /= grid[b];
      }
      E(i, 0) = 1;
      for (int k = 1; k < K; ++k) {
        std::complex<double> e = 1;
        for (int b = 0; b < d; ++b) {
          const long period = 2L * grid[b];
          long j = (static_cast<long>(basis.harmonic(k)[b]) * (2L * index[b] + 1)) % period;
          e *= roots[b][j < 0 ? j + period : j];
        }
        E(i, 2 * k - 1) = e.real();
        E(i, 2 * k) = e.imag();
      }
    }
    for (size_t j = 0; j < coefficients.size(); ++j)
      values[j].noalias() = E.topRows(count) * coefficients[j].transpose();
    for (long i = 0; i < count; ++i) {
      for (size_t j = 0; j < coefficients.size(); ++j) z[j] = values[j].row(i).transpose();
      const Eigen::VectorXd defined = definitions.evaluate(angles[i], z);
      if (defined.size() != n)
        throw std::invalid_argument("CheckDefinitions: the definitions give " +
                                    std::to_string(defined.size()) + " values for " +
                                    std::to_string(n) + " variables");
      for (int v = 0; v < n; ++v) {
        double diff = std::abs(z[0](v) - defined(v));
        if (!std::isfinite(diff)) diff = std::numeric_limits<double>::infinity();
        if (std::isfinite(defined(v))) scale(v) = std::max(scale(v), std::abs(defined(v)));
        if (diff > worst(v)) worst(v) = diff, worst_at[v] = angles[i];
      }
    }
  }

  // Scale: the variable's own size, but never below a millionth of the
  // largest variable's, so that one that vanishes (an odd function's mean)
  // is not judged on round-off relative to nothing.
  const double largest = std::max(scale.maxCoeff(), 1e-300);
  for (int v = 0; v < n; ++v) {
    const double s = std::max(scale(v), 1e-6 * largest);
    double tail = 0;
    for (int k = 1; k < K; ++k)
      if (4 * level[k] > 3 * max_level)
        tail = std::max(tail, std::hypot(coefficients[0](v, 2 * k - 1), coefficients[0](v, 2 * k)));
    check.tail = std::max(check.tail, tail / s);
    const double e = worst(v) / s;
    if (e > check.error || (check.worst_variable.empty() && e >= check.error)) {
      check.error = e;
      check.worst_variable = solution.variables()[v].name;
      check.worst_angles = worst_at[v];
    }
  }
  check.tolerance = std::clamp(options.truncation_factor * check.tail, options.floor, options.ceiling);
  check.physical = check.error <= check.tolerance;
  check.worst_time = d == 1 && !check.worst_angles.empty() && solution.frequencies()[0] > 0
                         ? check.worst_angles[0] / solution.frequencies()[0]
                         : std::numeric_limits<double>::quiet_NaN();
  check.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return check;
}

}  // namespace rmhb

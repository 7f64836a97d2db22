#include "rmhb/harmonic_monodromy.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <Eigen/Eigenvalues>

#include "rmhb/collocation_residual.h"

namespace rmhb {
namespace {

constexpr int kLevels = 4;  // step halvings extrapolated: order 2 kLevels

// Why the method does not apply to this problem and solution, or "".
std::string OutOfScope(const HarmonicBalanceProblem& problem, const HarmonicSolution& solution) {
  if (problem.frequencies.size() != 1 || solution.frequencies().size() != 1)
    return "periodic solutions only (one base frequency)";
  for (const Variable& v : problem.system.variables())
    if (v.role == VariableRole::kAuxiliary)
      return "the recast has auxiliaries (" + v.name + " = " + v.definition + "): not an ODE in its states";
  for (const Equation& eq : problem.system.equations())
    if (!eq.balance_constant) return "an equation is pinned at t = 0 (a recast auxiliary)";
  // Romberg's extrapolation needs smooth coefficients; a kink's jump in the
  // linearisation leaves the trapezoidal rule at O(h^2).
  if (problem.system.HasNonSmooth()) return "piecewise-smooth terms (the linearisation jumps at the switches)";
  return "";
}

// R(t_s) = -B(t_s)^-1 A(t_s) at every sample, into rates (n x n S, sample s
// in columns s n ..), and max_s |R|_inf; false when B is singular somewhere.
// Fixed-size matrices for two to four states (no allocation per sample).
template <int N>
bool RatesOf(const Eigen::MatrixXd& value, const Eigen::MatrixXd& derivative, int n, Eigen::MatrixXd* rates,
             double* largest, int* singular_at) {
  using Matrix = Eigen::Matrix<double, N, N>;
  const long samples = value.rows();
  rates->resize(n, n * samples);
  Matrix A(n, n), B(n, n);
  Eigen::PartialPivLU<Matrix> lu(n);
  *largest = 0;
  for (long s = 0; s < samples; ++s) {
    for (int i = 0; i < n; ++i)
      for (int v = 0; v < n; ++v) A(i, v) = value(s, i * n + v), B(i, v) = derivative(s, i * n + v);
    Matrix R;
    if constexpr (N == Eigen::Dynamic) {
      lu.compute(B);
      if (!(lu.rcond() > 1e-12)) return *singular_at = static_cast<int>(s), false;
      R = -lu.solve(A);
    } else {
      // Cofactors, with the determinant against the size of B as the test.
      const double size = B.cwiseAbs().maxCoeff();
      if (!(std::abs(B.determinant()) > 1e-12 * std::pow(size, n))) return *singular_at = static_cast<int>(s), false;
      R = -B.inverse() * A;
    }
    rates->middleCols(s * n, n) = R;
    *largest = std::max(*largest, R.cwiseAbs().rowwise().sum().maxCoeff());
  }
  return true;
}

// R at the S samples of one period (SampledPartials of the solution); "" or
// why not (B singular: a DAE; not a square first-order system).
std::string SampledRates(const HarmonicBalanceProblem& problem, const HarmonicSolution& solution, int samples,
                         Eigen::MatrixXd* rates, double* largest) {
  CollocationResidual residual(problem, solution.basis(), Sampling::Uniform(samples));
  const Eigen::VectorXd x = residual.Pack(solution.coefficients(), solution.frequencies());
  Eigen::MatrixXd value, derivative;
  if (!residual.SampledPartials(x, &value, &derivative)) return "not a square system of first-order equations";
  const int n = solution.num_variables();
  int singular_at = -1;
  bool ok = false;
  switch (n) {
    case 2: ok = RatesOf<2>(value, derivative, n, rates, largest, &singular_at); break;
    case 3: ok = RatesOf<3>(value, derivative, n, rates, largest, &singular_at); break;
    case 4: ok = RatesOf<4>(value, derivative, n, rates, largest, &singular_at); break;
    default: ok = RatesOf<Eigen::Dynamic>(value, derivative, n, rates, largest, &singular_at);
  }
  if (!ok) {
    std::ostringstream why;
    why << "dg/dz' is singular at sample " << singular_at << " of " << samples << ": a differential-algebraic system";
    return why.str();
  }
  if (!rates->allFinite()) return "non-finite partial derivatives along the solution";
  return "";
}

// The trapezoidal rule over one period on every stride-th sample:
// (I - h/2 R_{s+1}) Phi_{s+1} = (I + h/2 R_s) Phi_s, Phi_0 = I.
template <int N>
Eigen::MatrixXd TrapezoidOf(const Eigen::MatrixXd& rates, int stride, double period) {
  using Matrix = Eigen::Matrix<double, N, N>;
  const int n = static_cast<int>(rates.rows()), samples = static_cast<int>(rates.cols()) / n;
  const double h = period * stride / samples;
  const Matrix I = Matrix::Identity(n, n);
  Matrix phi = I, next = rates.leftCols(n), here;
  Eigen::PartialPivLU<Matrix> lu(n);
  for (int s = 0; s < samples; s += stride) {
    here = next;
    next = rates.middleCols(((s + stride) % samples) * n, n);
    const Matrix step = (I + 0.5 * h * here) * phi;
    if constexpr (N == Eigen::Dynamic) {
      lu.compute(I - 0.5 * h * next);
      phi = lu.solve(step);
    } else {
      // Cofactors: I - h/2 R is within O(h |R|) <= 0.05 of I, well conditioned.
      phi = (I - 0.5 * h * next).inverse() * step;
    }
  }
  return phi;
}

Eigen::MatrixXd Trapezoid(const Eigen::MatrixXd& rates, int stride, double period) {
  switch (rates.rows()) {
    case 2: return TrapezoidOf<2>(rates, stride, period);
    case 3: return TrapezoidOf<3>(rates, stride, period);
    case 4: return TrapezoidOf<4>(rates, stride, period);
    default: return TrapezoidOf<Eigen::Dynamic>(rates, stride, period);
  }
}

// Romberg over kLevels halvings of the step; *change: the last correction,
// relative to max(1, max|Phi|).
Eigen::MatrixXd Extrapolated(const Eigen::MatrixXd& rates, double period, double* change) {
  std::vector<Eigen::MatrixXd> column;
  for (int level = 0; level < kLevels; ++level) column.push_back(Trapezoid(rates, 1 << (kLevels - 1 - level), period));
  double factor = 1;
  for (int k = 1; k < kLevels; ++k) {
    factor *= 4;
    for (int level = kLevels - 1; level >= k; --level) {
      const Eigen::MatrixXd correction = (column[level] - column[level - 1]) / (factor - 1);
      if (level == kLevels - 1 && k == kLevels - 1) *change = correction.cwiseAbs().maxCoeff();
      column[level] += correction;
    }
  }
  const Eigen::MatrixXd& phi = column[kLevels - 1];
  *change /= std::max(1.0, phi.cwiseAbs().maxCoeff());
  return phi;
}

}  // namespace

std::string HarmonicMonodromyOptions::IsValid() const {
  if (!(tolerance > 0) || !std::isfinite(tolerance)) return "tolerance must be finite and > 0";
  if (!(max_step_rate > 0) || !std::isfinite(max_step_rate)) return "max_step_rate must be finite and > 0";
  if (max_steps < 64) return "max_steps must be >= 64";
  return "";
}

void DeflateTrivialMultiplier(const Eigen::MatrixXd& M, const Eigen::VectorXd& flow, Multipliers* multipliers,
                              int* trivial) {
  const int n = static_cast<int>(M.rows());
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(flow.normalized());
  const Eigen::MatrixXd basis = qr.householderQ();
  const Eigen::MatrixXd Q = basis.rightCols(n - 1);
  const Eigen::VectorXd along = basis.col(0);
  multipliers->clear();
  multipliers->push_back(along.dot(M * along));
  *trivial = 0;
  if (n > 1) {
    const Eigen::VectorXcd mu = Eigen::EigenSolver<Eigen::MatrixXd>(Q.transpose() * M * Q, false).eigenvalues();
    multipliers->insert(multipliers->end(), mu.data(), mu.data() + mu.size());
  }
}

MonodromyResult HarmonicMonodromy(const HarmonicBalanceProblem& problem, const HarmonicSolution& solution,
                                  const HarmonicMonodromyOptions& options, int* suggested_samples) {
  const auto start = std::chrono::steady_clock::now();
  if (const std::string why = options.IsValid(); !why.empty())
    throw std::invalid_argument("HarmonicMonodromy: " + why);
  if (solution.num_variables() != problem.system.num_variables())
    throw std::invalid_argument("HarmonicMonodromy: the solution has " + std::to_string(solution.num_variables()) +
                                " variables, the system " + std::to_string(problem.system.num_variables()));
  MonodromyResult result;
  result.integrator = "harmonic balance linearisation (trapezoidal rule, Romberg to order 8)";
  auto finish = [&](std::string message) {
    result.message = std::move(message);
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  };
  if (std::string why = OutOfScope(problem, solution); !why.empty()) return finish(why);
  // Every perturbation counts, not only those a symmetry of the solution keeps.
  HarmonicBalanceProblem full = problem;
  full.symmetries.clear();
  full.frequencies = solution.frequencies();
  const double period = 2 * M_PI / solution.frequencies()[0];
  // At least twice the harmonics (the grid must hold the basis), a power of two.
  int least = 64;
  while (least < 2 * solution.basis().num_coefficients() + 2) least *= 2;
  int samples = least;
  while (samples < options.initial_samples && 2 * samples <= options.max_steps) samples *= 2;
  Eigen::MatrixXd rates, phi;
  for (;;) {
    double largest = 0, change = 0;
    if (std::string why = SampledRates(full, solution, samples, &rates, &largest); !why.empty()) return finish(why);
    const double needed = largest * period / options.max_step_rate;
    if (needed > samples && samples < options.max_steps) {
      while (samples < needed && samples < options.max_steps) samples *= 2;
      continue;
    }
    phi = Extrapolated(rates, period, &change);
    if (change <= options.tolerance) {
      // The smallest grid whose correction would fall under the tolerance
      // (h^6, below), with 20 % to spare, and never below the rate's need.
      if (suggested_samples) {
        const double wanted = std::max(needed, 1.2 * samples * std::pow(change / options.tolerance, 1.0 / 6));
        *suggested_samples = least;
        while (*suggested_samples < wanted && 2 * *suggested_samples <= options.max_steps) *suggested_samples *= 2;
      }
      break;
    }
    if (2 * samples > options.max_steps) {
      std::ostringstream why;
      why << "the extrapolated monodromy changes by " << change << " (relative) > " << options.tolerance << " at "
          << samples << " steps per period (max_steps " << options.max_steps << ")";
      return finish(why.str());
    }
    // The last correction falls like h^6 (Romberg's order-6 and order-8
    // estimates differ by the former's error): the grid that meets it.
    const double factor = std::pow(change / options.tolerance, 1.0 / 6);
    const double target = 1.2 * factor * samples;
    int next = 2 * samples;
    while (next < target && 2 * next <= options.max_steps) next *= 2;
    samples = next;
  }
  if (problem.num_unknown_frequencies() > 0) {
    Eigen::VectorXd flow(solution.num_variables());
    for (int j = 0; j < flow.size(); ++j) flow(j) = solution.Derivative(j, 0.0);
    if (!(flow.norm() > 0)) return finish("an autonomous solution at rest: no flow direction to deflate");
    DeflateTrivialMultiplier(phi, flow, &result.multipliers, &result.trivial);
  } else {
    const Eigen::VectorXcd mu = Eigen::EigenSolver<Eigen::MatrixXd>(phi, false).eigenvalues();
    result.multipliers.assign(mu.data(), mu.data() + mu.size());
  }
  result.ok = true;
  return finish("");
}

}  // namespace rmhb

#include "rmhb/hill_stability.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/UmfPackSupport>
#include <Spectra/GenEigsSolver.h>

#include "rmhb/sampling.h"

namespace rmhb {
namespace {

struct Candidate {
  std::complex<double> lambda;
  double centroid;
};

// y = (J + sigma B)^-1 (-B x) for Spectra: its eigenvalues mu = 1 / (lambda -
// sigma) of J v = lambda (-B) v, largest |mu| for lambda nearest sigma.
class ShiftInvert {
 public:
  using Scalar = double;
  ShiftInvert(const Eigen::SparseMatrix<double>& J, const Eigen::SparseMatrix<double>& B, double sigma)
      : B_(B), shifted_(J + sigma * B) {
    lu_.compute(shifted_);
    if (lu_.info() != Eigen::Success)
      throw std::runtime_error("Hill's method: J + sigma B is singular at the shift (UMFPACK)");
  }
  Eigen::Index rows() const { return B_.rows(); }
  Eigen::Index cols() const { return B_.cols(); }
  void perform_op(const double* x, double* y) const {
    const Eigen::Map<const Eigen::VectorXd> in(x, B_.cols());
    Eigen::Map<Eigen::VectorXd>(y, B_.rows()) = lu_.solve(Eigen::VectorXd(-(B_ * in)));
  }

 private:
  const Eigen::SparseMatrix<double>& B_;
  Eigen::SparseMatrix<double> shifted_;  // UMFPACK's solves read it again
  Eigen::UmfPackLU<Eigen::SparseMatrix<double>> lu_;
};

// Mean harmonic index of a perturbation p(t) = sum_k c_k e^{i k w t}, weighted
// by |c_k|^2: the copy lambda + i m w of an exponent shifts it by -m.
double HarmonicCentroid(const Eigen::VectorXcd& v, int variables, int coefficients) {
  double moment = 0, weight = 0;
  for (int j = 0; j < variables; ++j) {
    const std::complex<double>* c = v.data() + static_cast<long>(j) * coefficients;
    weight += std::norm(c[0]);
    for (int k = 1; 2 * k < coefficients; ++k) {
      const std::complex<double> a = c[2 * k - 1], b = c[2 * k], i(0, 1);
      const double plus = std::norm(0.5 * (a - i * b)), minus = std::norm(0.5 * (a + i * b));
      moment += k * (plus - minus);
      weight += plus + minus;
    }
  }
  return weight > 0 ? moment / weight : 0;
}

// Keeps, per differential state, the candidate whose eigenvector is most
// central, one per class lambda + i m w.
void SelectPhysical(std::vector<Candidate> candidates, int states, double w,
                    HillStabilityReport* report) {
  report->eigenvalues = static_cast<int>(candidates.size());
  report->exponents.clear();
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return std::abs(a.centroid) < std::abs(b.centroid);
  });
  // A real exponent with a negative multiplier sits on the zone boundary:
  // lambda +- i w/2 are equally central; keep one.
  auto same_modulo_w = [&](std::complex<double> a, std::complex<double> b) {
    const double m = std::round((a.imag() - b.imag()) / w);
    return m != 0 && std::abs(a - b - std::complex<double>(0, m * w)) < 1e-6 * (w + std::abs(a));
  };
  for (const Candidate& c : candidates) {
    if (static_cast<int>(report->exponents.size()) == states) break;
    bool copy = false;
    for (const auto& kept : report->exponents) copy = copy || same_modulo_w(c.lambda, kept);
    if (!copy) report->exponents.push_back(c.lambda);
  }
}

// The exponents nearest the imaginary axis by shift-invert Arnoldi
// (Spectra) on the sparse Hill matrices, more of them until every
// differential state has its physical one (METHOD.md s.17).
void ShiftInvertExponents(CollocationResidual& residual, const Eigen::VectorXd& x, int n, int C,
                          double w, const HarmonicBasis& basis, HillStabilityReport* report) {
  Eigen::SparseMatrix<double> A, B;
  residual.LinearizationParts(x, &A, &B);
  const int size = n * C;
  std::vector<Eigen::Triplet<double>> d;
  for (int j = 0; j < n; ++j)
    for (int k = 1; k < basis.size(); ++k) {
      const double rate = basis.Frequency(k, {w});
      d.emplace_back(j * C + 2 * k - 1, j * C + 2 * k, rate);
      d.emplace_back(j * C + 2 * k, j * C + 2 * k - 1, -rate);
    }
  Eigen::SparseMatrix<double> D(size, size);
  D.setFromTriplets(d.begin(), d.end());
  const Eigen::SparseMatrix<double> J = A + B * D;
  // The differential states: variables whose derivative enters (B's columns).
  std::vector<bool> differential(n, false);
  for (int k = 0; k < B.outerSize(); ++k)
    if (B.col(k).nonZeros() > 0) differential[k / C] = true;
  const int states = static_cast<int>(std::count(differential.begin(), differential.end(), true));
  // A small real shift, off the trivial exponent 0 of an autonomous orbit.
  const double sigma = 1e-2 * w;
  ShiftInvert op(J, B, sigma);
  for (int nev = std::min(size - 2, 4 * states + 8);; nev = std::min(size - 2, 2 * nev)) {
    Spectra::GenEigsSolver<ShiftInvert> eigs(op, nev, std::min(size, 2 * nev + 1));
    eigs.init();
    eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12);
    if (eigs.info() != Spectra::CompInfo::Successful)
      throw std::runtime_error("Hill's method: shift-invert Arnoldi (Spectra) did not converge");
    const Eigen::VectorXcd mu = eigs.eigenvalues();
    const Eigen::MatrixXcd vectors = eigs.eigenvectors();
    std::vector<Candidate> candidates;
    for (long i = 0; i < mu.size(); ++i)
      if (std::abs(mu(i)) > 0) candidates.push_back({sigma + 1.0 / mu(i), HarmonicCentroid(vectors.col(i), n, C)});
    SelectPhysical(std::move(candidates), states, w, report);
    if (static_cast<int>(report->exponents.size()) == states || nev == size - 2) break;
  }
  if (static_cast<int>(report->exponents.size()) < states)
    throw std::runtime_error("Hill's method: shift-invert found " + std::to_string(report->exponents.size()) +
                             " of " + std::to_string(states) + " Floquet exponents");
}

}  // namespace

const char* ToString(HillEigensolver e) {
  switch (e) {
    case HillEigensolver::kAuto: return "auto";
    case HillEigensolver::kDense: return "dense";
    case HillEigensolver::kShiftInvert: return "shift-invert";
  }
  return "?";
}

std::string HillStabilityReport::BriefReport() const {
  std::ostringstream out;
  out.precision(6);
  out << (stable ? "stable" : "unstable") << " (Hill, order " << order << ", " << ToString(eigensolver)
      << "): max Re(lambda) "
      << max_real_part << ", multipliers";
  for (size_t i = 0; i < multipliers.size(); ++i)
    out << (static_cast<int>(i) == trivial ? " [" : " ") << multipliers[i]
        << (static_cast<int>(i) == trivial ? " trivial]" : "");
  return out.str();
}

HillStabilityReport HillStability(const HarmonicBalanceProblem& problem,
                                  const HarmonicSolution& solution, const HillOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (problem.frequencies.size() != 1 || solution.basis().num_bases() != 1)
    throw std::invalid_argument("Hill's method: periodic solutions only (one base frequency)");
  if (solution.num_variables() != problem.system.num_variables())
    throw std::invalid_argument("Hill's method: the solution has " +
                                std::to_string(solution.num_variables()) + " variables, the system " +
                                std::to_string(problem.system.num_variables()));
  for (int i = 0; i < problem.system.num_equations(); ++i)
    if (!problem.system.equations()[i].balance_constant)
      throw std::invalid_argument(
          "Hill's method: equation " + std::to_string(i + 1) +
          " is pinned at t = 0 (a recast auxiliary defined through its derivative); its free "
          "constant adds a spurious neutral exponent. Use the Floquet multipliers of the "
          "original equations");

  // All perturbations count, not only those a symmetry of the solution keeps.
  HarmonicBalanceProblem full = problem;
  full.symmetries.clear();
  full.frequencies = solution.frequencies();
  const HarmonicBasis& basis = solution.basis();
  // Alias-free: the blocks are then those of classical harmonic balance.
  const int samples = SamplesForRule(full.system, basis, SamplingRule::kRhb)[0];
  CollocationResidual residual(full, basis, Sampling::Uniform(samples));
  const Eigen::VectorXd x = residual.Pack(solution.coefficients(), solution.frequencies());
  const int n = solution.num_variables(), C = basis.num_coefficients();
  const double w = solution.frequencies()[0];
  HillStabilityReport report;
  report.order = basis.order();
  report.size = n * C;
  report.eigensolver = options.eigensolver != HillEigensolver::kAuto ? options.eigensolver
                       : report.size <= options.dense_limit     ? HillEigensolver::kDense
                                                                 : HillEigensolver::kShiftInvert;
  if (report.eigensolver == HillEigensolver::kDense) {
    Eigen::MatrixXd value_part, derivative_part;
    residual.LinearizationParts(x, &value_part, &derivative_part);
    // J = A + B D(w): d/dt of (a_k cos + b_k sin)(k w t) has cos-coefficient
    // k w b_k and sin-coefficient -k w a_k.
    Eigen::MatrixXd jacobian = value_part;
    for (int j = 0; j < n; ++j)
      for (int k = 1; k < basis.size(); ++k) {
        const double rate = basis.Frequency(k, {w});
        const long c = static_cast<long>(j) * C;
        jacobian.col(c + 2 * k) += rate * derivative_part.col(c + 2 * k - 1);
        jacobian.col(c + 2 * k - 1) -= rate * derivative_part.col(c + 2 * k);
      }
    Eigen::GeneralizedEigenSolver<Eigen::MatrixXd> solver(jacobian, -derivative_part, true);
    if (solver.info() != Eigen::Success)
      throw std::runtime_error("Hill's method: the generalised eigensolver (QZ) did not converge");
    std::vector<Candidate> candidates;
    const Eigen::VectorXcd alphas = solver.alphas();
    const Eigen::VectorXd betas = solver.betas();
    const Eigen::MatrixXcd vectors = solver.eigenvectors();
    // Infinite eigenvalues belong to the algebraic equations (B singular).
    const double finite_bound = 1e6 * (1 + basis.order() * w);
    for (long i = 0; i < alphas.size(); ++i) {
      if (std::abs(alphas(i)) >= finite_bound * std::abs(betas(i))) continue;
      candidates.push_back({alphas(i) / betas(i), HarmonicCentroid(vectors.col(i), n, C)});
    }
    const int states = static_cast<int>(std::lround(double(candidates.size()) / C));
    SelectPhysical(std::move(candidates), states, w, &report);
  } else {
    ShiftInvertExponents(residual, x, n, C, w, basis, &report);
  }
  std::sort(report.exponents.begin(), report.exponents.end(),
            [](auto a, auto b) { return a.real() > b.real(); });
  const double period = 2 * M_PI / w;
  for (const auto& l : report.exponents) report.multipliers.push_back(std::exp(l * period));
  if (problem.num_unknown_frequencies() > 0 && !report.exponents.empty()) {
    report.trivial = 0;
    for (size_t i = 1; i < report.exponents.size(); ++i)
      if (std::abs(report.exponents[i]) < std::abs(report.exponents[report.trivial]))
        report.trivial = static_cast<int>(i);
  }
  report.max_real_part = -HUGE_VAL;
  for (size_t i = 0; i < report.exponents.size(); ++i)
    if (static_cast<int>(i) != report.trivial)
      report.max_real_part = std::max(report.max_real_part, report.exponents[i].real());
  report.stable = report.max_real_part < -options.margin * w;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace rmhb

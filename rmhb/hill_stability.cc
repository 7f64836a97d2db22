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

#include "rmhb/dense_factorization.h"
#include "rmhb/sampling.h"

namespace rmhb {
namespace {

struct Candidate {
  std::complex<double> lambda;
  double centroid;
};

// y = (J + sigma B)^-1 (-B x) for Spectra: its eigenvalues mu = 1 / (lambda -
// sigma) of J v = lambda (-B) v, largest |mu| for lambda nearest sigma. A
// torus' Hill matrices are nearly dense (every harmonic couples to most
// others), where UMFPACK's sparse solves cost ten times a dense LU's: up to
// kDenseShiftInvert rows, a fill above a tenth is factorised densely.
class ShiftInvert {
 public:
  using Scalar = double;
  static constexpr long kDenseShiftInvert = 6000;
  ShiftInvert(const Eigen::SparseMatrix<double>& J, const Eigen::SparseMatrix<double>& B, double sigma)
      : B_(B), shifted_(J + sigma * B) {
    const long n = shifted_.rows();
    dense_ = n <= kDenseShiftInvert && shifted_.nonZeros() > n * n / 10;
    if (dense_) {
      dense_lu_.compute(Eigen::MatrixXd(shifted_));
      if (dense_lu_.singular())
        throw std::runtime_error("Hill's method: J + sigma B is singular at the shift (dense LU)");
      return;
    }
    lu_.compute(shifted_);
    if (lu_.info() != Eigen::Success)
      throw std::runtime_error("Hill's method: J + sigma B is singular at the shift (UMFPACK)");
  }
  Eigen::Index rows() const { return B_.rows(); }
  Eigen::Index cols() const { return B_.cols(); }
  void perform_op(const double* x, double* y) const {
    const Eigen::Map<const Eigen::VectorXd> in(x, B_.cols());
    const Eigen::VectorXd rhs = -(B_ * in);
    Eigen::Map<Eigen::VectorXd> out(y, B_.rows());
    if (dense_)
      out = dense_lu_.solve(rhs);
    else
      out = lu_.solve(rhs);
  }

 private:
  const Eigen::SparseMatrix<double>& B_;
  Eigen::SparseMatrix<double> shifted_;  // UMFPACK's solves read it again
  bool dense_ = false;
  DenseLu dense_lu_;  // LAPACK's (rmhb/dense_factorization.h)
  Eigen::UmfPackLU<Eigen::SparseMatrix<double>> lu_;
};

// Mean harmonic index of a perturbation p(t) = sum_k c_k e^{i k.w t},
// weighted by |c_k|^2, one component per base: the copy lambda + i m.w of
// an exponent shifts it by -m. Its Euclidean length is how far from the
// central harmonics the eigenvector sits.
double HarmonicCentroid(const Eigen::VectorXcd& v, const HarmonicBasis& basis, int variables) {
  const int C = basis.num_coefficients();
  std::vector<double> moment(basis.num_bases(), 0.0);
  double weight = 0;
  for (int j = 0; j < variables; ++j) {
    const std::complex<double>* c = v.data() + static_cast<long>(j) * C;
    weight += std::norm(c[0]);
    for (int k = 1; k < basis.size(); ++k) {
      const std::complex<double> a = c[2 * k - 1], b = c[2 * k], i(0, 1);
      const double plus = std::norm(0.5 * (a - i * b)), minus = std::norm(0.5 * (a + i * b));
      for (int base = 0; base < basis.num_bases(); ++base) moment[base] += basis.harmonic(k)[base] * (plus - minus);
      weight += plus + minus;
    }
  }
  if (weight == 0) return 0;
  double squared = 0;
  for (double m : moment) squared += (m / weight) * (m / weight);
  return std::sqrt(squared);
}

// Whether a and b are copies of one exponent: a - b = i k.w for a harmonic
// k != 0 of the basis (either sign). One base: k = round(Im(a - b) / w).
bool SameExponent(std::complex<double> a, std::complex<double> b, const HarmonicBasis& basis,
                  const std::vector<double>& w) {
  const double w_max = *std::max_element(w.begin(), w.end());
  const double tolerance = 1e-6 * (w_max + std::abs(a));
  const std::complex<double> d = a - b;
  if (std::abs(d.real()) >= tolerance) return false;
  if (basis.num_bases() == 1) {
    const double m = std::round(d.imag() / w[0]);
    return m != 0 && std::abs(d - std::complex<double>(0, m * w[0])) < tolerance;
  }
  for (int k = 1; k < basis.size(); ++k)
    if (std::abs(std::abs(d.imag()) - std::abs(basis.Frequency(k, w))) < tolerance) return true;
  return false;
}

// Keeps, per differential state, the candidate whose eigenvector is most
// central, one per class lambda + i k.w.
void SelectPhysical(std::vector<Candidate> candidates, int states, const HarmonicBasis& basis,
                    const std::vector<double>& w, HillStabilityReport* report) {
  report->eigenvalues = static_cast<int>(candidates.size());
  report->exponents.clear();
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return std::abs(a.centroid) < std::abs(b.centroid);
  });
  // A real exponent with a negative multiplier sits on the zone boundary:
  // lambda +- i w/2 are equally central; keep one.
  for (const Candidate& c : candidates) {
    if (static_cast<int>(report->exponents.size()) == states) break;
    bool copy = false;
    for (const auto& kept : report->exponents) copy = copy || SameExponent(c.lambda, kept, basis, w);
    if (!copy) report->exponents.push_back(c.lambda);
  }
}

// The exponents nearest the imaginary axis by shift-invert Arnoldi
// (Spectra) on the sparse Hill matrices, more of them until every
// differential state has its physical one (METHOD.md s.17).
void ShiftInvertExponents(CollocationResidual& residual, const Eigen::VectorXd& x, int n,
                          const std::vector<double>& w, const HarmonicBasis& basis, HillStabilityReport* report) {
  const int C = basis.num_coefficients();
  Eigen::SparseMatrix<double> A, B;
  residual.LinearizationParts(x, &A, &B);
  const int size = n * C;
  std::vector<Eigen::Triplet<double>> d;
  for (int j = 0; j < n; ++j)
    for (int k = 1; k < basis.size(); ++k) {
      const double rate = basis.Frequency(k, w);
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
  const double sigma = 1e-2 * *std::min_element(w.begin(), w.end());
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
      if (std::abs(mu(i)) > 0) candidates.push_back({sigma + 1.0 / mu(i), HarmonicCentroid(vectors.col(i), basis, n)});
    SelectPhysical(std::move(candidates), states, basis, w, report);
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
      << "): max Re(lambda) " << max_real_part << (bases == 1 ? ", multipliers" : ", exponents");
  const std::vector<std::complex<double>>& listed = bases == 1 ? multipliers : exponents;
  for (size_t i = 0; i < listed.size(); ++i) {
    const bool is_trivial = std::count(trivials.begin(), trivials.end(), static_cast<int>(i)) > 0;
    out << (is_trivial ? " [" : " ") << listed[i] << (is_trivial ? " trivial]" : "");
  }
  return out.str();
}

namespace {

void CheckApplies(const HarmonicBalanceProblem& problem, const HarmonicSolution& solution) {
  if (problem.frequencies.size() != static_cast<size_t>(solution.basis().num_bases()))
    throw std::invalid_argument("Hill's method: the problem has " + std::to_string(problem.frequencies.size()) +
                                " base frequencies, the solution " + std::to_string(solution.basis().num_bases()));
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
}

// A v = lambda B v by LAPACK's QZ (dggev). Eigen's RealQZ stopped without
// converging when B has many zero rows (a recast's algebraic auxiliaries,
// from order 20 on); dggev deflates those infinite eigenvalues, and at the
// dense limit (602 rows, Van der Pol at order 150) costs what Eigen's did:
// 16-17 ms, the median of 15 runs either way.
GeneralizedEigen QzEigen(Eigen::MatrixXd A, Eigen::MatrixXd B) {
  try {
    return SolveGeneralizedEigen(std::move(A), std::move(B));
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string("Hill's method: ") + e.what());
  }
}

// The dense generalised eigenproblem J v = lambda (-B) v (QZ), every finite
// eigenvalue a candidate.
void DenseExponents(CollocationResidual& residual, const Eigen::VectorXd& x, int n,
                    const std::vector<double>& w, const HarmonicBasis& basis, HillStabilityReport* report) {
  const int C = basis.num_coefficients();
  Eigen::MatrixXd value_part, derivative_part;
  residual.LinearizationParts(x, &value_part, &derivative_part);
  // J = A + B D(w): d/dt of (a_k cos + b_k sin)(k.w t) has cos-coefficient
  // k.w b_k and sin-coefficient -k.w a_k.
  Eigen::MatrixXd jacobian = value_part;
  for (int j = 0; j < n; ++j)
    for (int k = 1; k < basis.size(); ++k) {
      const double rate = basis.Frequency(k, w);
      const long c = static_cast<long>(j) * C;
      jacobian.col(c + 2 * k) += rate * derivative_part.col(c + 2 * k - 1);
      jacobian.col(c + 2 * k - 1) -= rate * derivative_part.col(c + 2 * k);
    }
  const GeneralizedEigen qz = QzEigen(std::move(jacobian), -derivative_part);
  std::vector<Candidate> candidates;
  const Eigen::VectorXcd& alphas = qz.alphas;
  const Eigen::VectorXd& betas = qz.betas;
  const Eigen::MatrixXcd& vectors = qz.vectors;
  // Infinite eigenvalues belong to the algebraic equations (B singular).
  double fastest = 0;
  for (int k = 1; k < basis.size(); ++k) fastest = std::max(fastest, std::abs(basis.Frequency(k, w)));
  const double finite_bound = 1e6 * (1 + fastest);
  for (long i = 0; i < alphas.size(); ++i) {
    if (std::abs(alphas(i)) >= finite_bound * std::abs(betas(i))) continue;
    candidates.push_back({alphas(i) / betas(i), HarmonicCentroid(vectors.col(i), basis, n)});
  }
  const int states = static_cast<int>(std::lround(double(candidates.size()) / C));
  SelectPhysical(std::move(candidates), states, basis, w, report);
}

// The `count` exponents closest to 0 are the free angles' (an autonomous
// orbit's phase, a torus' unknown angles); the verdict is on the others.
void MarkTrivial(int count, double margin, double w_min, HillStabilityReport* report) {
  std::vector<int> order(report->exponents.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return std::abs(report->exponents[a]) < std::abs(report->exponents[b]); });
  order.resize(std::min<size_t>(order.size(), count));
  std::sort(order.begin(), order.end());
  report->trivials = order;
  report->trivial = order.empty() ? -1 : order[0];
  report->max_real_part = -HUGE_VAL;
  for (size_t i = 0; i < report->exponents.size(); ++i)
    if (!std::binary_search(order.begin(), order.end(), static_cast<int>(i)))
      report->max_real_part = std::max(report->max_real_part, report->exponents[i].real());
  report->stable = report->max_real_part < -margin * w_min;
}

}  // namespace

HillStabilityReport HillStability(const HarmonicBalanceProblem& problem,
                                  const HarmonicSolution& solution, const HillOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CheckApplies(problem, solution);
  // All perturbations count, not only those a symmetry of the solution keeps.
  HarmonicBalanceProblem full = problem;
  full.symmetries.clear();
  full.frequencies = solution.frequencies();
  const HarmonicBasis& basis = solution.basis();
  // Alias-free: the blocks are then those of classical harmonic balance.
  const std::vector<int> samples = SamplesForRule(full.system, basis, SamplingRule::kRhb);
  CollocationResidual residual(full, basis,
                               samples.size() == 1 ? Sampling::Uniform(samples[0]) : Sampling::Torus(samples));
  const Eigen::VectorXd x = residual.Pack(solution.coefficients(), solution.frequencies());
  const int n = solution.num_variables();
  const std::vector<double>& w = solution.frequencies();
  HillStabilityReport report;
  report.order = basis.order();
  report.bases = basis.num_bases();
  report.size = n * basis.num_coefficients();
  report.eigensolver = options.eigensolver != HillEigensolver::kAuto ? options.eigensolver
                       : report.size <= options.dense_limit     ? HillEigensolver::kDense
                                                                 : HillEigensolver::kShiftInvert;
  if (report.eigensolver == HillEigensolver::kDense)
    DenseExponents(residual, x, n, w, basis, &report);
  else
    ShiftInvertExponents(residual, x, n, w, basis, &report);
  std::sort(report.exponents.begin(), report.exponents.end(),
            [](auto a, auto b) { return a.real() > b.real(); });
  // A torus has no period, so no multipliers.
  if (report.bases == 1)
    for (const auto& l : report.exponents) report.multipliers.push_back(std::exp(l * (2 * M_PI / w[0])));
  const int free_angles = std::min(report.bases, problem.num_unknown_frequencies());
  MarkTrivial(free_angles, options.margin, *std::min_element(w.begin(), w.end()), &report);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace rmhb

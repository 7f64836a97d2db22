// Experiment toward a matrix-free Newton-Krylov solver for large orders (not
// in the library yet): how many GMRES iterations does the Newton system
// J dx = -F of Van der Pol at order N need when right-preconditioned by
//   - the dense Jacobian at a lower order N_low, factorised (LU), on the
//     harmonics up to N_low and the frequency, and
//   - the 2x2 diagonal blocks of J for each higher harmonic (block Jacobi)?
// Newton runs at order N from the order-N_low solution; every step's GMRES
// solution is compared with the dense LU step. J is assembled densely here
// and J v is a dense product, standing in for the O(M log M) FFT product a
// matrix-free solver would use, so the times show the preconditioner's cost
// (LU at N_low) against the dense LU at N, and the iteration counts what the
// products would cost.
//   build/tests/benchmarks/newton_krylov_benchmark [eps N N_low ...]
// (default: 20 1000 500, 20 1000 250, 20 1000 125).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "examples/example_system.h"
#include "rmhb/collocation_residual.h"
#include "rmhb/dense_factorization.h"
#include "rmhb/harmonic_balance.h"

using namespace rmhb;

namespace {

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct Level {
  HarmonicBasis basis;
  std::unique_ptr<CollocationResidual> residual;
};

Level MakeLevel(const HarmonicBalanceProblem& problem, int order) {
  Level level{HarmonicBasis::Periodic(order), nullptr};
  std::vector<int> alias_free;
  const std::vector<int> m =
      SamplesForRule(problem.system, level.basis, SamplingRule::kRhb, &alias_free);
  level.residual = std::make_unique<CollocationResidual>(problem, level.basis,
                                                         Sampling::Uniform(m[0]), true);
  return level;
}

// Right-preconditioned GMRES (modified Gram-Schmidt, Givens rotations, no
// restart) for A x = b to a relative residual `tolerance`.
template <class Product, class Preconditioner>
Eigen::VectorXd Gmres(const Product& A, const Preconditioner& P, const Eigen::VectorXd& b,
                      double tolerance, int max_iterations, int* iterations, double* relative) {
  const long n = b.size();
  const double norm_b = b.norm();
  Eigen::MatrixXd V(n, max_iterations + 1), Z(n, max_iterations);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(max_iterations + 1, max_iterations);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(max_iterations + 1);
  std::vector<double> c(max_iterations), s(max_iterations);
  V.col(0) = b / norm_b;
  g(0) = norm_b;
  int k = 0;
  *relative = 1;
  for (; k < max_iterations && *relative > tolerance; ++k) {
    Z.col(k) = P(V.col(k));
    Eigen::VectorXd v = A(Z.col(k));
    for (int j = 0; j <= k; ++j) {
      H(j, k) = V.col(j).dot(v);
      v -= H(j, k) * V.col(j);
    }
    H(k + 1, k) = v.norm();
    V.col(k + 1) = v / H(k + 1, k);
    for (int j = 0; j < k; ++j) {
      const double t = c[j] * H(j, k) + s[j] * H(j + 1, k);
      H(j + 1, k) = -s[j] * H(j, k) + c[j] * H(j + 1, k);
      H(j, k) = t;
    }
    const double d = std::hypot(H(k, k), H(k + 1, k));
    c[k] = H(k, k) / d;
    s[k] = H(k + 1, k) / d;
    H(k, k) = d;
    H(k + 1, k) = 0;
    g(k + 1) = -s[k] * g(k);
    g(k) = c[k] * g(k);
    *relative = std::abs(g(k + 1)) / norm_b;
  }
  *iterations = k;
  const Eigen::VectorXd y = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
  return Z.leftCols(k) * y;
}

void Run(double eps, int order, int low_order) {
  const examples::ExampleSetup e = examples::BuildExample("vanderpol", {{"eps", eps}});
  HarmonicBalanceOptions o;
  o.order = low_order;
  const HarmonicBalanceSummary low = SolveHarmonicBalance(e.problem, e.guess, o);
  std::printf("# eps = %g, N = %d, preconditioner N_low = %d (solved: %s)\n", eps, order, low_order,
              low.BriefReport().c_str());
  if (!low.converged()) return;
  Level high = MakeLevel(e.problem, order), coarse = MakeLevel(e.problem, low_order);
  // Van der Pol condensed: unknowns [C coefficients of x, w], rows [C rows
  // of the u equation, the phase condition]; harmonic k at 2k-1, 2k.
  const int n = high.residual->num_unknowns(), n_low = coarse.residual->num_unknowns();
  const int C = n - 1, C_low = n_low - 1;
  auto low_index = [&](int i) { return i < C_low ? i : (i == C ? C_low : -1); };
  Eigen::VectorXd x = high.residual->Pack(low.solution->OnBasis(high.basis).coefficients(),
                                          low.solution->frequencies());
  Eigen::VectorXd F(n), F_low(n_low);
  Eigen::MatrixXd J(n, n), J_low(n_low, n_low);
  std::printf("%-4s %10s %6s %10s %12s %10s %10s %10s\n", "step", "max|F|", "gmres", "rel.res",
              "|dx-LU|/|dx|", "LU(N)[s]", "LU(low)[s]", "gmres[s]");
  for (int step = 0; step < 8; ++step) {
    high.residual->Evaluate(x, &F, &J);
    const double residual = F.cwiseAbs().maxCoeff();
    if (residual < 1e-14) {
      std::printf("%-4d %10.3e  converged\n", step, residual);
      break;
    }
    auto t = std::chrono::steady_clock::now();
    DenseLu lu;
    const Eigen::VectorXd dense_step = lu.compute(J).solve(-F);
    const double lu_seconds = Since(t);

    t = std::chrono::steady_clock::now();
    Eigen::VectorXd x_low(n_low);
    x_low.head(C_low) = x.head(C_low);
    x_low(C_low) = x(C);
    coarse.residual->Evaluate(x_low, &F_low, &J_low);
    DenseLu lu_low;
    lu_low.compute(J_low);
    std::vector<Eigen::Matrix2d> blocks;
    for (int i = C_low; i < C; i += 2) blocks.push_back(J.block(i, i, 2, 2).inverse());
    const double low_seconds = Since(t);
    auto precondition = [&](const Eigen::VectorXd& r) {
      Eigen::VectorXd r_low(n_low), y(n);
      for (int i = 0; i < n; ++i)
        if (low_index(i) >= 0) r_low(low_index(i)) = r(i);
      const Eigen::VectorXd y_low = lu_low.solve(r_low);
      for (int i = 0; i < n; ++i)
        if (low_index(i) >= 0) y(i) = y_low(low_index(i));
      // Written out: GCC 12 warns (falsely) inside AVX for a 2x2 product on a segment.
      for (int b = 0; b < (C - C_low) / 2; ++b) {
        const int i = C_low + 2 * b;
        const Eigen::Matrix2d& B = blocks[b];
        y(i) = B(0, 0) * r(i) + B(0, 1) * r(i + 1);
        y(i + 1) = B(1, 0) * r(i) + B(1, 1) * r(i + 1);
      }
      return y;
    };
    auto product = [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(J * v); };
    t = std::chrono::steady_clock::now();
    int iterations = 0;
    double relative = 0;
    const Eigen::VectorXd dx = Gmres(product, precondition, -F, 1e-12, 400, &iterations, &relative);
    const double gmres_seconds = Since(t);
    std::printf("%-4d %10.3e %6d %10.2e %12.2e %10.3f %10.3f %10.3f\n", step, residual, iterations,
                relative, (dx - dense_step).norm() / dense_step.norm(), lu_seconds, low_seconds,
                gmres_seconds);
    std::fflush(stdout);
    x += dx;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<double> args;
  for (int i = 1; i < argc; ++i) args.push_back(std::atof(argv[i]));
  if (args.empty()) args = {20, 1000, 500, 20, 1000, 250, 20, 1000, 125};
  if (args.size() % 3 != 0) {
    std::fprintf(stderr, "usage: newton_krylov_benchmark [eps N N_low]...\n");
    return 1;
  }
  for (size_t i = 0; i < args.size(); i += 3) {
    const int order = static_cast<int>(args[i + 1]), low_order = static_cast<int>(args[i + 2]);
    if (!(args[i] > 0) || low_order < 1 || order <= low_order) {
      std::fprintf(stderr, "newton_krylov_benchmark: need eps > 0 and N > N_low >= 1\n");
      return 1;
    }
    Run(args[i], order, low_order);
  }
  return 0;
}

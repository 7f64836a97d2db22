// The Newton factorisation alone: Eigen's PartialPivLU against LAPACK's
// dgetrf from OpenBLAS (rmhb::DenseLu) on one and two threads, error against
// time. The matrix has a dominant diagonal and the right-hand side comes from
// a known solution, so the error column is each solve's own.
//   build/tests/benchmarks/dense_factorization_benchmark [n ...]   (default 1000 2000 4000)
// n = 12000 needs ~3.5 GB and a minute per row on one core.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "rmhb/dense_factorization.h"

namespace {

double Seconds(const std::function<void()>& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes;
  for (int i = 1; i < argc; ++i) sizes.push_back(std::atoi(argv[i]));
  if (sizes.empty()) sizes = {1000, 2000, 4000};
  std::printf("%-7s %-22s %10s %10s %12s\n", "n", "factorisation", "time[s]", "GFlop/s",
              "max|x-exact|");
  for (int n : sizes) {
    if (n < 1) {
      std::fprintf(stderr, "dense_factorization_benchmark: sizes must be >= 1\n");
      return 1;
    }
    std::srand(1);
    Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
    A.diagonal().array() += 2 * std::sqrt(double(n));
    const Eigen::VectorXd exact = Eigen::VectorXd::LinSpaced(n, -1, 1), b = A * exact;
    const double flops = 2.0 / 3.0 * double(n) * n * n;
    auto row = [&](const std::string& name, double seconds, const Eigen::VectorXd& x) {
      std::printf("%-7d %-22s %10.3f %10.1f %12.3e\n", n, name.c_str(), seconds,
                  flops / seconds * 1e-9, (x - exact).cwiseAbs().maxCoeff());
      std::fflush(stdout);
    };
    {
      Eigen::PartialPivLU<Eigen::MatrixXd> lu;
      const double t = Seconds([&] { lu.compute(A); });
      row("Eigen PartialPivLU", t, lu.solve(b));
    }
    for (int threads : {1, 2}) {
      rmhb::SetDenseFactorizationThreads(threads);
      rmhb::DenseLu lu;
      const double t = Seconds([&] { lu.compute(A); });
      row("OpenBLAS dgetrf, " + std::to_string(threads) + "T", t, lu.solve(b));
    }
  }
  return 0;
}

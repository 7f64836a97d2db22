// A user's program: build a polynomial system with the C++ API, solve it with
// RHB, print the summary. Forced Duffing x'' + 0.1 x' + x + x^3 = cos(1.5 t),
// written as x' = v, v' = -0.1 v - x - x^3 + cos(1.5 t).

#include <cstdio>

#include "rmhb/harmonic_balance.h"

int main() {
  rmhb::PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("v");
  const rmhb::Polynomial x = s.Var("x"), v = s.Var("v");
  s.AddEquation(s.D("x") - v);
  s.AddEquation(s.D("v") + 0.1 * v + x + rmhb::Pow(x, 3) - rmhb::Polynomial::Cos({1}, 1.0));

  const double w = 1.5;
  rmhb::HarmonicBalanceProblem problem{s, {w}, {false}, {}};
  // Start near the resonant (upper) branch: x = 1.5 cos(w t), v = x'.
  const rmhb::HarmonicSolution guess = rmhb::HarmonicSolution::FromAngles(
      rmhb::HarmonicBasis::Periodic(1), {w}, s.variables(), [w](const std::vector<double>& th) {
        return Eigen::Vector2d(1.5 * std::cos(th[0]), -1.5 * w * std::sin(th[0])).eval();
      });

  rmhb::HarmonicBalanceOptions options;
  options.order = 20;
  const rmhb::HarmonicBalanceSummary summary = rmhb::SolveHarmonicBalance(problem, guess, options);
  std::printf("%s", summary.FullReport().c_str());
  if (!summary.converged()) return 1;
  const rmhb::HarmonicSolution& x_of_t = *summary.solution;
  std::printf("x(0) = %.15f, first harmonic (%.15f, %.15f)\n", x_of_t.Value(0, 0.0),
              x_of_t.coefficients()(0, 1), x_of_t.coefficients()(0, 2));
  return 0;
}

// Parameter continuation: branch length, points, time and error against
// references, for increasing order N. Run on demand:
//   build/tests/benchmarks/continuation_benchmark
// - Duffing x'' + 0.1 x' + x + x^3 = 0.5 cos(w t), w from 0.5 to 3 by
//   pseudo-arclength through both folds: fold frequencies against the same
//   trace at N = 30, and the largest CVODE (Adams, rtol 1e-13) deviation over
//   one period from every 4th point of the branch.
// - Relativistic oscillator, beta from 0.5 to 0.99 (natural and
//   pseudo-arclength): the largest amplitude and frequency errors over the
//   branch against the exact energy quadrature.
// Times: one whole TraceBranch call (first solve, every corrector, tangent,
// fold location and Hill stability per point), best of 3.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "examples/example_model.h"
#include "examples/example_system.h"
#include "examples/references.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/continuation.h"
#include "rmhb/pipeline/monodromy.h"

using namespace rmhb;

namespace {

// The trace as a program makes it from a model (rmhb/pipeline/monodromy.h):
// a forcing frequency is only set at each value, another parameter rebuilds
// the example (METHOD.md s.19). Stability by the harmonic balance
// linearisation or Hill's method, as before: no CVODE monodromy.
ContinuationSummary Trace(const std::string& example, std::map<std::string, double> fixed,
                          const std::string& parameter, double from, double to,
                          ContinuationMethod method, int order, double* seconds) {
  fixed[parameter] = from;
  ContinuationProblem problem =
      ModelContinuationProblem(examples::ExampleModel(example, fixed), parameter, from, to);
  problem.monodromy = nullptr;
  const HarmonicSolution guess = examples::BuildExample(example, fixed).guess;
  ContinuationOptions options;
  options.method = method;
  options.harmonic_balance.order = order;
  ContinuationSummary best;
  *seconds = HUGE_VAL;
  for (int run = 0; run < 3; ++run) {
    const auto start = std::chrono::steady_clock::now();
    ContinuationSummary s = TraceBranch(problem, guess, options);
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (t < *seconds) *seconds = t, best = std::move(s);
  }
  return best;
}

std::vector<double> Folds(const ContinuationSummary& s) {
  std::vector<double> folds;
  for (const ContinuationPoint& p : s.points)
    if (p.fold) folds.push_back(p.parameter);
  return folds;
}

void Duffing() {
  const std::map<std::string, double> fixed = {{"c", 0.1}, {"F", 0.5}};
  double seconds;
  const std::vector<double> reference =
      Folds(Trace("duffing", fixed, "w", 0.5, 3, ContinuationMethod::kPseudoArclength, 30, &seconds));
  std::printf("Duffing x'' + 0.1 x' + x + x^3 = 0.5 cos(w t), w = 0.5 -> 3, pseudo-arclength\n");
  std::printf("reference folds (N = 30): w = %.15f, %.15f\n", reference[0], reference[1]);
  std::printf("%4s %7s %6s %6s %10s %10s %12s %12s %14s\n", "N", "points", "folds", "steps", "arclength",
              "time ms", "ms/point", "fold error", "CVODE max err");
  for (int order : {5, 8, 10, 15, 20}) {
    const ContinuationSummary s =
        Trace("duffing", fixed, "w", 0.5, 3, ContinuationMethod::kPseudoArclength, order, &seconds);
    const std::vector<double> folds = Folds(s);
    double fold_error = folds.size() == 2 ? 0 : NAN;
    for (size_t i = 0; i < folds.size() && i < 2; ++i)
      fold_error = std::max(fold_error, std::abs(folds[i] - reference[i]));
    double cvode = 0;
    for (size_t i = 0; i < s.points.size(); i += 4) {
      const ContinuationPoint& p = s.points[i];
      std::map<std::string, double> values = fixed;
      values["w"] = p.parameter;
      const examples::ExampleSetup e = examples::BuildExample("duffing", values);
      const auto v = integrators::ValidateTrajectory(
          {e.original.dimension(), e.original.rhs}, [&](double t) { return e.original.state(p.solution, t); },
          2 * M_PI / p.parameter, false, 201);
      cvode = std::max(cvode, v.ok ? v.max_error : NAN);
    }
    std::printf("%4d %7zu %6d %6d %10.4f %10.1f %12.2f %12.1e %14.1e  %s\n", order, s.points.size(),
                s.num_folds, s.accepted_steps + s.rejected_steps, s.arclength, seconds * 1e3,
                seconds * 1e3 / s.points.size(), fold_error, cvode, ToString(s.status));
  }
}

void Relativistic() {
  std::printf("\nRelativistic x'' + (1 - x'^2)^(3/2) x = 0, x'(0) = beta; error: max over the branch of\n"
              "|amplitude - exact| and |w - exact| (energy quadrature)\n");
  std::printf("%-17s %4s %4s %7s %10s %12s %12s %12s\n", "method", "to", "N", "points", "time ms", "ms/point",
              "amp error", "freq error");
  for (double to : {0.95, 0.99})
    for (ContinuationMethod method : {ContinuationMethod::kNatural, ContinuationMethod::kPseudoArclength})
      for (int order : {25, 55, 80}) {
        double seconds;
        const ContinuationSummary s = Trace("relativistic", {}, "beta", 0.5, to, method, order, &seconds);
        double amplitude = 0, frequency = 0;
        for (const ContinuationPoint& p : s.points) {
          amplitude = std::max(amplitude, std::abs(p.solution.Amplitude(0) -
                                                   examples::RelativisticAmplitude(p.parameter)));
          frequency = std::max(frequency, std::abs(p.solution.frequencies()[0] -
                                                   2 * M_PI / examples::RelativisticPeriod(p.parameter)));
        }
        std::printf("%-17s %4.2f %4d %7zu %10.1f %12.2f %12.1e %12.1e  %s\n", ToString(method), to, order,
                    s.points.size(), seconds * 1e3, seconds * 1e3 / s.points.size(), amplitude, frequency,
                    ToString(s.status));
      }
}

}  // namespace

int main() {
  Duffing();
  Relativistic();
  return 0;
}

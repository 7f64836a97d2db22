// Error against run time for increasing N (the paper's Tables 2 and 3), with
// Newton, Levenberg-Marquardt and Tikhonov side by side. Run on demand:
//   build/tests/benchmarks/rhb_benchmark [system ...]
// Times are the median of repeated solves from the example's starting guess,
// the whole SolveHarmonicBalance call (basis, FFTW plans, order continuation).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "examples/example_system.h"
#include "examples/references.h"
#include "rmhb/harmonic_balance.h"

using namespace rmhb;

namespace {

struct Case {
  std::string system;
  std::map<std::string, double> parameters;
  std::vector<int> orders;
  std::string error_name;
  std::function<double(const HarmonicSolution&)> error;
};

double MedianSeconds(const std::function<void()>& f) {
  std::vector<double> t;
  const auto begin = std::chrono::steady_clock::now();
  while (t.size() < 5 || (t.size() < 50 && std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count() < 0.5)) {
    const auto s = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - s).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> wanted(argv + 1, argv + argc);
  const double w_pendulum = examples::PendulumFrequency(1.5);
  const double A_rel = examples::RelativisticAmplitude(0.85);
  std::vector<Case> cases = {
      {"pendulum", {{"theta0", 1.5}}, {5, 10, 15, 20, 25, 30}, "max|theta - exact| over a period",
       [](const HarmonicSolution& s) {
         const double T = 2 * M_PI / s.frequencies()[0];
         double worst = 0;
         for (int i = 0; i <= 500; ++i)
           worst = std::max(worst, std::abs(s.Value(0, T * i / 500) - examples::PendulumAngle(1.5, T * i / 500)));
         return worst;
       }},
      {"pendulum", {{"theta0", 1.5}}, {25}, "|w - exact|",
       [w_pendulum](const HarmonicSolution& s) { return std::abs(s.frequencies()[0] - w_pendulum); }},
      {"relativistic", {{"beta", 0.85}}, {15, 25, 35, 45, 55, 65}, "|amplitude - exact|",
       [A_rel](const HarmonicSolution& s) { return std::abs(s.Amplitude(0) - A_rel); }},
      {"vanderpol", {{"eps", 1.0}}, {10, 20, 30, 40}, "|period - reference|",
       [](const HarmonicSolution& s) { return std::abs(2 * M_PI / s.frequencies()[0] - 6.6632868593231301897); }},
      {"vanderpol", {{"eps", 10.0}}, {200, 300, 340}, "|period - reference|",
       [](const HarmonicSolution& s) { return std::abs(2 * M_PI / s.frequencies()[0] - 19.07836956693901407); }},
  };
  std::printf("%-14s %-5s %-9s %6s %6s %12s %12s %6s  %s\n", "system", "N", "solver", "M", "iters",
              "error", "time[ms]", "status", "error measure");
  for (const Case& c : cases) {
    if (!wanted.empty() && std::find(wanted.begin(), wanted.end(), c.system) == wanted.end()) continue;
    const examples::ExampleSetup e = examples::BuildExample(c.system, c.parameters);
    for (int N : c.orders) {
      for (SolverMethod m : {SolverMethod::kNewton, SolverMethod::kLevenbergMarquardt, SolverMethod::kTikhonov}) {
        HarmonicBalanceOptions o;
        o.order = N;
        o.solver.method = m;
        HarmonicBalanceSummary s;
        const double seconds = MedianSeconds([&] { s = SolveHarmonicBalance(e.problem, e.guess, o); });
        const double err = s.solution ? c.error(*s.solution) : NAN;
        std::printf("%-14s %-5d %-9s %6d %6d %12.3e %12.3f %6s  %s\n", c.system.c_str(), N, ToString(m),
                    s.samples[0], s.solver.iterations, err, seconds * 1e3,
                    s.converged() ? "ok" : "FAIL", c.error_name.c_str());
        std::fflush(stdout);
      }
    }
  }
  return 0;
}

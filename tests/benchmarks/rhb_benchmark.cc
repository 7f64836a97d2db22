// Error against run time for increasing N (the paper's Tables 2 and 3), with
// Newton, Levenberg-Marquardt and Tikhonov side by side; then the extreme
// cases (Van der Pol relaxation against tight CVODE periods, the pendulum near
// its separatrix, the relativistic oscillator near c) with Newton, and order
// selection by --tol. Run on demand:
//   build/tests/benchmarks/rhb_benchmark [system ...]
// (Van der Pol eps = 50 at N = 6000 takes minutes and ~4 GB: only when
// "vanderpol-50" is named.) "mems": equilibration against no scaling, on the
// forced Duffing in SI units and in good units (SolverOptions::scaling).
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
  std::vector<SolverMethod> solvers = {SolverMethod::kNewton, SolverMethod::kLevenbergMarquardt,
                                       SolverMethod::kTikhonov};
  double tolerance = 0;  // > 0: order selection from each order in `orders`
  bool condense = true;
  std::string label = "";  // selects the case on the command line (default: system)
};


double MedianSeconds(const std::function<void()>& f) {
  std::vector<double> t;
  const auto begin = std::chrono::steady_clock::now();
  // One run is enough when it takes seconds (the extreme cases).
  while (t.size() < 5 && !(t.size() == 1 && t[0] > 1.0)) {
    const auto s = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - s).count());
  }
  while ( (t.size() < 50 && std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count() < 0.5)) {
    const auto s = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - s).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// m x'' + c x' + k x + k3 x^3 = F0 cos(w t) as x' = v, m v' + ... (the m
// kept on the derivative, as a model file writes it). The MEMS resonator of
// examples/models/mems-duffing.yaml is units = 1e-6 (metres), time = 1e-4
// (seconds per unit); units = time = 1 is the nondimensional duffing.
HarmonicBalanceProblem ForcedDuffing(double length, double time, double w) {
  const double m = 1e-9, w0 = 1 / time, k = m * w0 * w0;  // k = 0.1 N/m in SI
  const double scale = length == 1 && time == 1 ? 1 / k : 1;  // nondimensional: m = k = 1
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("v");
  const Polynomial x = s.Var("x"), v = s.Var("v");
  s.AddEquation(s.D("x") - v);
  s.AddEquation(scale * m * s.D("v") + scale * 0.1 * m * w0 * v + scale * k * x +
                scale * k / (length * length) * Pow(x, 3) - Polynomial::Cos({1}, scale * k * length));
  return HarmonicBalanceProblem{s, {w / time}, {false}, {}};
}

HarmonicSolution DuffingGuess(const HarmonicBalanceProblem& p, double length) {
  const double w = p.frequencies[0];
  return HarmonicSolution::FromAngles(HarmonicBasis::Periodic(1), {w}, p.system.variables(),
                                      [w, length](const std::vector<double>& th) {
                                        return Eigen::Vector2d(2 * length * std::cos(th[0]),
                                                               -2 * length * w * std::sin(th[0]))
                                            .eval();
                                      });
}

// Error of the SI solution mapped back (relative to the largest coefficient)
// against the nondimensional one at the same N, and the time of each, with
// and without equilibration; then the plain Duffing at N = 20 (w = 1.5, the
// api_example point) to show what scaling costs where it is not needed.
void RunMemsScaling() {
  const double length = 1e-6, time = 1e-4;
  std::printf("\n%-24s %-5s %-12s %6s %12s %12s %12s  %s\n", "system", "N", "scaling", "iters",
              "error", "time[ms]", "rcond J", "error measure");
  const HarmonicBalanceProblem si = ForcedDuffing(length, time, 2.0);
  const HarmonicBalanceProblem unit = ForcedDuffing(1, 1, 2.0);
  for (int N : {5, 10, 15, 20, 30}) {
    HarmonicBalanceOptions o;
    o.order = N;
    const HarmonicBalanceSummary reference = SolveHarmonicBalance(unit, DuffingGuess(unit, 1), o);
    const Eigen::MatrixXd& X = reference.solution->coefficients();
    for (Scaling scaling : {Scaling::kEquilibrate, Scaling::kNone}) {
      o.solver.scaling = scaling;
      HarmonicBalanceSummary s;
      const double seconds = MedianSeconds([&] { s = SolveHarmonicBalance(si, DuffingGuess(si, length), o); });
      const double error = s.solution ? (s.solution->coefficients().row(0) / length - X.row(0))
                                                .cwiseAbs()
                                                .maxCoeff() /
                                            X.row(0).cwiseAbs().maxCoeff()
                                      : NAN;
      std::printf("%-24s %-5d %-12s %6d %12.3e %12.3f %12.2e  %s\n", "mems-duffing (SI)", N, ToString(scaling),
                  s.solver.iterations, error, seconds * 1e3, s.solver.reciprocal_condition,
                  "max|x_k/1e-6 - X_k| / max|X_k|, X solved nondimensionally");
    }
  }
  const HarmonicBalanceProblem plain = ForcedDuffing(1, 1, 1.5);
  HarmonicBalanceOptions o;
  o.order = 20;
  o.solver.scaling = Scaling::kNone;
  HarmonicBalanceSummary none;
  MedianSeconds([&] { none = SolveHarmonicBalance(plain, DuffingGuess(plain, 0.75), o); });
  const Eigen::MatrixXd X = none.solution->coefficients();
  for (Scaling scaling : {Scaling::kEquilibrate, Scaling::kNone}) {
    o.solver.scaling = scaling;
    HarmonicBalanceSummary s;
    const double seconds = MedianSeconds([&] { s = SolveHarmonicBalance(plain, DuffingGuess(plain, 0.75), o); });
    const double difference = (s.solution->coefficients() - X).cwiseAbs().maxCoeff();
    std::printf("%-24s %-5d %-12s %6d %12.3e %12.3f %12.2e  %s\n", "duffing w=1.5", 20, ToString(scaling),
                s.solver.iterations, difference, seconds * 1e3, s.solver.reciprocal_condition,
                "max|c - c(unscaled)|");
  }
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
  // The extreme cases: Newton only (L-M and Tikhonov fail or crawl here).
  const std::vector<SolverMethod> newton = {SolverMethod::kAuto};
  auto pendulum_frequency = [](double theta0) {
    return [theta0](const HarmonicSolution& s) {
      return std::abs(s.frequencies()[0] - examples::PendulumFrequency(theta0));
    };
  };
  auto relativistic = [](double beta) {
    return [beta](const HarmonicSolution& s) {
      return std::max(std::abs(s.Amplitude(0) - examples::RelativisticAmplitude(beta)),
                      std::abs(s.frequencies()[0] - 2 * M_PI / examples::RelativisticPeriod(beta)));
    };
  };
  // CVODE periods, computed once when a selected case first needs one.
  std::map<double, double> vdp_period;
  auto vdp = [&vdp_period](double eps) {
    return [&vdp_period, eps](const HarmonicSolution& s) {
      if (!vdp_period.count(eps)) {
        const auto start = std::chrono::steady_clock::now();
        vdp_period[eps] = examples::VanDerPolPeriodByCvode(eps);
        std::printf("# Van der Pol eps = %g: CVODE BDF rtol 1e-15 period %.17g (%.2f s)\n", eps,
                    vdp_period[eps],
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      }
      return std::abs(2 * M_PI / s.frequencies()[0] - vdp_period[eps]);
    };
  };
  const std::string vdp_error = "|period - CVODE BDF period|";
  std::vector<Case> extreme = {
      {"vanderpol", {{"eps", 5.0}}, {60, 100, 140}, vdp_error, vdp(5), newton, 0, true, "vanderpol-5"},
      {"vanderpol", {{"eps", 10.0}}, {320}, vdp_error + " (not condensed)", vdp(10), newton, 0, false, "vanderpol-10"},
      {"vanderpol", {{"eps", 10.0}}, {280, 300, 320, 340}, vdp_error, vdp(10), newton, 0, true, "vanderpol-10"},
      {"vanderpol", {{"eps", 20.0}}, {800, 1000, 1100, 1200}, vdp_error, vdp(20), newton, 0, true, "vanderpol-20"},
      {"vanderpol", {{"eps", 50.0}}, {6000}, vdp_error, vdp(50), newton, 0, true, "vanderpol-50"},
      {"pendulum", {{"theta0", 3.0}}, {40, 60}, "|w - exact|", pendulum_frequency(3.0), newton, 0, true, "pendulum-3.0"},
      {"pendulum", {{"theta0", 3.1}}, {60, 80}, "|w - exact|", pendulum_frequency(3.1), newton, 0, true, "pendulum-3.1"},
      {"pendulum", {{"theta0", 3.14}}, {100, 128, 160}, "|w - exact|", pendulum_frequency(3.14), newton, 0, true, "pendulum-3.14"},
      {"relativistic", {{"beta", 0.95}}, {80, 110}, "max(|A - exact|, |w - exact|)", relativistic(0.95), newton, 0, true, "relativistic-0.95"},
      {"relativistic", {{"beta", 0.99}}, {150, 300}, "max(|A - exact|, |w - exact|)", relativistic(0.99), newton, 0, true, "relativistic-0.99"},
      // Order selection: N is the start; the row shows the order chosen.
      {"pendulum", {{"theta0", 3.14}}, {25}, "|w - exact|, --tol 1e-10", pendulum_frequency(3.14), newton, 1e-10, true, "tol"},
      {"relativistic", {{"beta", 0.99}}, {55}, "max(|A - exact|, |w - exact|), --tol 1e-10", relativistic(0.99), newton, 1e-10, true, "tol"},
      {"vanderpol", {{"eps", 10.0}}, {40}, vdp_error + ", --tol 1e-11", vdp(10), newton, 1e-11, true, "tol"},
  };
  // Selection: no argument runs all but eps = 50; a system name its paper
  // rows; "extreme" every extreme row but eps = 50; a label its own rows.
  auto named = [&](const std::string& name) {
    return std::find(wanted.begin(), wanted.end(), name) != wanted.end();
  };
  if (wanted.empty() || named("mems")) RunMemsScaling();
  if (!wanted.empty() && wanted.size() == 1 && named("mems")) return 0;
  for (Case& c : cases) c.label = c.system;
  for (auto it = cases.begin(); it != cases.end();)
    it = wanted.empty() || named(it->system) ? it + 1 : cases.erase(it);
  for (Case& c : extreme) {
    if (!(named(c.label) || ((wanted.empty() || named("extreme")) && c.label != "vanderpol-50")))
      continue;
    c.system += " " + (c.label == "tol" ? std::string("tol") : c.label.substr(c.label.find('-') + 1));
    cases.push_back(c);
  }
  std::printf("%-18s %-5s %-9s %6s %6s %12s %12s %6s  %s\n", "system", "N", "solver", "M", "iters",
              "error", "time[ms]", "status", "error measure");
  for (const Case& c : cases) {
    const std::string example = c.system.substr(0, c.system.find(' '));
    const examples::ExampleSetup e = examples::BuildExample(example, c.parameters);
    for (int N : c.orders) {
      for (SolverMethod m : c.solvers) {
        HarmonicBalanceOptions o;
        o.order = N;
        o.solver.method = m;
        o.tolerance = c.tolerance;
        o.condense_definitions = c.condense;
        // The size check counts the Jacobian before condensation (24003^2
        // doubles at eps = 50, N = 6000); the condensed one is a quarter.
        o.max_jacobian_bytes = 8.0 * (1L << 30);
        HarmonicBalanceSummary s;
        const double seconds = MedianSeconds([&] { s = SolveHarmonicBalance(e.problem, e.guess, o); });
        const double err = s.solution ? c.error(*s.solution) : NAN;
        std::printf("%-18s %-5d %-9s %6d %6d %12.3e %12.3f %6s  %s\n", c.system.c_str(), s.order, ToString(m),
                    s.samples[0], s.solver.iterations, err, seconds * 1e3,
                    s.converged() ? "ok" : "FAIL", c.error_name.c_str());
        std::fflush(stdout);
      }
    }
  }
  return 0;
}

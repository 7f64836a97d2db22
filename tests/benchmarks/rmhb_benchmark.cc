// Quasi-periodic RMHB (rmhb/METHOD.md s.6): error against run time for p = 1..p_max
// on the asymmetric pendulum (two unknown base frequencies) and the forced
// Van der Pol oscillator (forcing known, limit cycle unknown), with the GCD
// rule beside the torus grid wherever it is feasible. Run on demand:
//   build/tests/benchmarks/rmhb_benchmark [asym-pendulum] [forced-vanderpol] [duffing-2tone]
// Times are medians of repeated SolveHarmonicBalance calls from the example's
// guess (basis, FFTW plans, Newton); the guess itself (a short simulation) is
// timed once per system and printed in the header.
//
// Errors are measured against CVODE (Adams, rtol 1e-13) on the ORIGINAL
// equations: the pendulum from its initial state over t in [0, 2000], the
// Van der Pol from the solution's own state at t = 0 (phases matched) over
// [0, 500]; the two-tone Duffing (periodic, 3:5 or 7:11) by the largest
// coefficient difference between the two samplings.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "examples/example_system.h"
#include "integrators/cvode_integrator.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/harmonic_balance.h"

using namespace rmhb;

namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

double MedianSeconds(const std::function<void()>& f) {
  std::vector<double> t;
  const auto begin = std::chrono::steady_clock::now();
  while (t.size() < 3 || (t.size() < 30 && Seconds(begin) < 0.5)) {
    const auto s = std::chrono::steady_clock::now();
    f();
    t.push_back(Seconds(s));
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

struct Row {
  std::string sampling = "-";
  int unknowns = 0;
  double milliseconds = NAN;
  double error = NAN;
  std::string status = "-";
  std::vector<double> w;
};

// Solves and times one configuration; a refused one (GCD rule) keeps the reason.
Row Run(const examples::ExampleSetup& e, const HarmonicBalanceOptions& o,
        const std::function<double(const HarmonicSolution&)>& error, std::string* refused) {
  Row row;
  HarmonicBalanceSummary s;
  try {
    s = SolveHarmonicBalance(e.problem, e.guess, o);
  } catch (const std::invalid_argument& why) {
    if (refused) *refused = why.what();
    row.status = "refused";
    return row;
  }
  row.milliseconds = 1e3 * MedianSeconds([&] { s = SolveHarmonicBalance(e.problem, e.guess, o); });
  row.sampling = s.sampling;
  row.unknowns = s.solver.num_unknowns;
  row.status = s.converged() ? "ok" : ToString(s.solver.status);
  if (s.solution) {
    row.w = s.solution->frequencies();
    row.error = error(*s.solution);
  }
  return row;
}

void Print(const char* basis, int p, const Row& r) {
  std::printf("  %-16s %3d  %-26s %6d  %10.3f  %10.3e  %-13s", basis, p, r.sampling.c_str(),
              r.unknowns, r.milliseconds, r.error, r.status.c_str());
  for (double w : r.w) std::printf(" %.12f", w);
  std::printf("\n");
  std::fflush(stdout);
}

void Header(const char* error_name) {
  std::printf("  %-16s %3s  %-26s %6s  %10s  %10s  %-13s %s\n", "basis", "p", "sampling", "unkn",
              "time[ms]", error_name, "status", "frequencies");
}

// Both samplings for one basis; the GCD rule is printed only when it is not
// refused, the reason once per system otherwise.
void Both(const examples::ExampleSetup& e, HarmonicBalanceOptions o, const char* basis, int p,
          const std::function<double(const HarmonicSolution&)>& error, std::string* gcd_refusal) {
  o.quasi_periodic_sampling = QuasiPeriodicSampling::kTorus;
  Print(basis, p, Run(e, o, error, nullptr));
  o.quasi_periodic_sampling = QuasiPeriodicSampling::kGcd;
  std::string why;
  const Row gcd = Run(e, o, error, &why);
  if (why.empty()) Print(basis, p, gcd);
  else if (gcd_refusal->empty()) *gcd_refusal = why;
}

void AsymmetricPendulum() {
  const auto begin = std::chrono::steady_clock::now();
  const examples::ExampleSetup e = examples::BuildExample("asym-pendulum");
  const double guess_ms = 1e3 * Seconds(begin);
  integrators::IntegratorOptions tight;
  tight.relative_tolerance = 1e-13;
  tight.absolute_tolerance = 1e-15;
  std::vector<double> times;
  for (int i = 0; i <= 8000; ++i) times.push_back(0.25 * i);
  const auto ref = integrators::IntegrateOde({4, e.original.rhs}, Eigen::Vector4d(0.1, 0.2, 0, 0),
                                             0.0, times, tight);
  auto error = [&](const HarmonicSolution& s) {
    double worst = 0;
    for (size_t i = 0; i < times.size(); ++i)
      for (int v = 0; v < 2; ++v)
        worst = std::max(worst, std::abs(s.Value(v, times[i]) - ref.trajectory.states(i, v)));
    return worst;
  };
  std::printf("\nasym-pendulum (kappa 0.01, x0 0.1, y0 0.2; both frequencies unknown)\n"
              "  guess from simulation: %.1f ms (w = %.9f %.9f)\n"
              "  error: max |x - cvode|, |y - cvode| over t in [0, 2000]; paper: p = 5 diamond, "
              "fixed FFT w = (0.9857, 0.9935), 8.24 s, 9.21e-3 (x), 3.9e-7 (y)\n",
              guess_ms, e.guess.frequencies()[0], e.guess.frequencies()[1]);
  Header("max error");
  std::string refused;
  // The adaptive index set (rmhb solve's default) for falling targets;
  // its row shows the target's exponent as p.
  for (int t = 4; t <= 12; t += 2) {
    HarmonicBalanceOptions o;
    o.order = e.default_order;
    o.shape = BasisShape::kAdaptive;
    o.tolerance = std::pow(10.0, -t);
    Both(e, o, "adaptive 1e-p", t, error, &refused);
  }
  // The paper's index set, for comparison (same guess, frequencies solved for).
  for (int p : {3, 5, 7, 9}) {
    HarmonicBalanceOptions o;
    o.order = p;
    Both(e, o, "diamond", p, error, &refused);
  }
  if (!refused.empty()) std::printf("  GCD rule: %s\n", refused.c_str());
}

void ForcedVanDerPol() {
  const auto begin = std::chrono::steady_clock::now();
  const examples::ExampleSetup e = examples::BuildExample("forced-vanderpol");
  const double guess_ms = 1e3 * Seconds(begin);
  integrators::OdeSystem ode{2, e.original.rhs};
  auto error = [&](const HarmonicSolution& s) {
    const auto r = integrators::ValidateTrajectory(
        ode, [&](double t) { return e.original.state(s, t); }, 500.0, false, 5001);
    return r.ok ? r.max_error : NAN;
  };
  std::printf("\nforced-vanderpol (eps 0.2, F 0.5, w 2.3; w1 = 2.3 known, w2 unknown)\n"
              "  guess from simulation: %.1f ms (w2 = %.9f)\n"
              "  error: max |(x, x') - cvode| over t in [0, 500], cvode started on the solution\n",
              guess_ms, e.guess.frequencies()[1]);
  Header("max error");
  std::string refused;
  for (int t = 4; t <= 12; t += 2) {
    HarmonicBalanceOptions o;
    o.order = e.default_order;
    o.shape = BasisShape::kAdaptive;
    o.tolerance = std::pow(10.0, -t);
    Both(e, o, "adaptive 1e-p", t, error, &refused);
  }
  for (int p : {5, 9, 13, 15}) {
    HarmonicBalanceOptions o;
    o.order = p;
    Both(e, o, "diamond", p, error, &refused);
  }
  if (!refused.empty()) std::printf("  GCD rule: %s\n", refused.c_str());
}

// Where the GCD rule is feasible: two known tones in ratio 3:5 and 7:11.
void DuffingTwoTone() {
  for (auto [w1, w2] : {std::pair{0.6, 1.0}, std::pair{0.7, 1.1}}) {
    const examples::ExampleSetup e = examples::BuildExample("duffing-2tone", {{"w1", w1}, {"w2", w2}});
    std::printf("\nduffing-2tone (w1 %.1f, w2 %.1f; both known): error = max coefficient "
                "difference, GCD rule vs torus grid\n", w1, w2);
    Header("difference");
    std::string refused;
    for (int p = 1; p <= 8; ++p) {
      HarmonicBalanceOptions o;
      o.order = p;
      HarmonicBalanceSummary torus = SolveHarmonicBalance(e.problem, e.guess, o);
      auto difference = [&](const HarmonicSolution& s) {
        return (s.coefficients() - torus.solution->coefficients()).cwiseAbs().maxCoeff();
      };
      Both(e, o, "diamond", p, difference, &refused);
    }
    if (!refused.empty()) std::printf("  GCD rule: %s\n", refused.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> wanted(argv + 1, argv + argc);
  auto run = [&](const char* name) {
    return wanted.empty() || std::find(wanted.begin(), wanted.end(), name) != wanted.end();
  };
  if (run("asym-pendulum")) AsymmetricPendulum();
  if (run("forced-vanderpol")) ForcedVanDerPol();
  if (run("duffing-2tone")) DuffingTwoTone();
  return 0;
}

// Tori along a parameter (issue 16; README "Tori"), against brute-force
// references that use no harmonic balance:
//  1. the weakly forced Van der Pol oscillator x'' - eps (1 - x^2) x' + x =
//     F cos(w t), eps 0.2, F 0.1 (tests/pipeline/models/weakly-forced-vdp.yaml),
//     w from 1.1 to 0.9 across the 1:1 locking tongue at diamond order 24:
//     each point's w2, outermost coefficients and Lyapunov verdict; at three
//     quasi-periodic points w2 against a long CVODE integration (the
//     rotation of the angle of (x, -x') by a weighted Birkhoff average, which
//     converges faster than any power of the span on a smooth torus: Das &
//     Yorke 2017); the tongue's edges against a bisection on the phase slips
//     of CVODE trajectories (locked: none over 4000 forcing periods);
//  2. the asymmetric pendulum (two unknown bases) continued in its amplitude
//     x0, every 10th point against CVODE over t in [0, 2000]. Its hand-made
//     beat basis at order 6 (1.6e-10 over [0, 2000]) is gone with issue 12's
//     per-example bases; on the diamond at p = 12 the trace stops at the
//     first step (outermost coefficients 2.4e-3): README, Known weaknesses.
// Run: build/tests/benchmarks/torus_benchmark [vdp|pendulum]   (from the repository root)

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "examples/example_model.h"
#include "integrators/cvode_integrator.h"
#include "rmhb/pipeline/branch.h"
#include "rmhb/pipeline/settings.h"

namespace {

using namespace rmhb;
constexpr double kEps = 0.2, kF = 0.1;

integrators::OdeSystem Vdp(double w) {
  return {2, [w](double t, const double* y, double* dy) {
            dy[0] = y[1];
            dy[1] = kEps * (1 - y[0] * y[0]) * y[1] - y[0] + kF * std::cos(w * t);
          }};
}

// The angle of (x, -x') turned in each of `periods` forcing periods after
// `transient` ones (sampled 32 times a period to unwrap it).
std::vector<double> PeriodTurns(double w, int transient, int periods, double rtol) {
  const double T = 2 * M_PI / w;
  integrators::IntegratorOptions o;
  o.relative_tolerance = rtol;
  o.absolute_tolerance = rtol * 1e-2;
  const auto settle = integrators::IntegrateOde(Vdp(w), Eigen::Vector2d(2, 0), 0, {transient * T}, o);
  const Eigen::VectorXd y0 = settle.trajectory.states.row(0).transpose();
  constexpr int kPer = 32;
  std::vector<double> times;
  for (int k = 0; k <= kPer * periods; ++k) times.push_back((transient + static_cast<double>(k) / kPer) * T);
  const auto r = integrators::IntegrateOde(Vdp(w), y0, transient * T, times, o);
  std::vector<double> turns(periods, 0.0);
  double previous = std::atan2(-y0(1), y0(0));
  for (int k = 1; k < r.trajectory.states.rows(); ++k) {
    const double angle = std::atan2(-r.trajectory.states(k, 1), r.trajectory.states(k, 0));
    turns[(k - 1) / kPer] += std::remainder(angle - previous, 2 * M_PI);
    previous = angle;
  }
  return turns;
}

// w2 = w * (mean turn per forcing period) / 2 pi, the mean by the weighted
// Birkhoff average (weights exp(-1 / (s (1 - s))), s in (0, 1)).
double BirkhoffW2(double w, int periods) {
  const std::vector<double> turns = PeriodTurns(w, 300, periods, 1e-13);
  double sum = 0, weights = 0;
  for (int n = 0; n < periods; ++n) {
    const double s = (n + 0.5) / periods, g = std::exp(-1 / (s * (1 - s)));
    sum += g * turns[n];
    weights += g;
  }
  return w * sum / weights / (2 * M_PI);
}

int Slips(double w) {
  constexpr int kWindow = 4000;
  double turned = 0;
  for (double t : PeriodTurns(w, 4000, kWindow, 1e-9)) turned += t;
  return static_cast<int>(std::lround(kWindow - turned / (2 * M_PI)));
}

// The edge between locked (no slip) and unlocked by bisection to `width`.
double BisectEdge(double locked, double unlocked, double width) {
  while (std::abs(unlocked - locked) > width) {
    const double mid = 0.5 * (locked + unlocked);
    (Slips(mid) == 0 ? locked : unlocked) = mid;
  }
  return 0.5 * (locked + unlocked);
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

void ForcedVanDerPol() {
  const char* file = "tests/pipeline/models/weakly-forced-vdp.yaml";
  SolveSettings settings;
  settings.order = 24;
  settings.shape = "diamond";
  settings.shape_given = true;
  const PreparedSolve prepared = PrepareSolve(LoadModel(file, {{"w", 1.1}}), settings);
  ContinueOptions o;
  o.parameter = "w";
  o.from = 1.1;
  o.to = 0.9;
  o.harmonic_balance = prepared.options;
  const auto start = std::chrono::steady_clock::now();
  const BranchSummary b = ContinueModel(prepared.model, prepared.guess, o);
  std::printf("== 1. forced Van der Pol eps 0.2, F 0.1, w 1.1 -> 0.9, diamond p = 24 (%.1f s)\n%s\n", Seconds(start),
              b.FullReport().c_str());
  // Three quasi-periodic points against the long integration.
  const auto& points = b.continuation.points;
  const size_t picks[] = {0, points.size() / 4, points.size() - 1};
  std::printf("%-16s %-20s %-20s %-9s %-9s %s\n", "w", "w2 (RMHB)", "w2 (CVODE, Birkhoff)", "|diff|",
              "outermost", "Lyapunov");
  for (size_t i : picks) {
    const double w = points[i].parameter, w2 = points[i].solution.frequencies()[1];
    const auto t0 = std::chrono::steady_clock::now();
    const double reference = BirkhoffW2(w, 3000);
    std::printf("%-16.12g %-20.15g %-20.15g %-9.1e %-9.1e %s (reference %.1f s)\n", w, w2, reference,
                std::abs(w2 - reference), b.reports[i].outermost, b.reports[i].lyapunov->BriefReport().c_str(),
                Seconds(t0));
  }
  for (const TongueReport& t : b.tongues) {
    if (!std::isfinite(t.near_edge) || !std::isfinite(t.far_edge)) continue;
    const auto t0 = std::chrono::steady_clock::now();
    const double centre = 0.5 * (t.near_edge + t.far_edge);
    const double near = BisectEdge(centre, t.near_edge + (t.near_edge - centre) * 0.2, 1e-5);
    const double far = BisectEdge(centre, t.far_edge + (t.far_edge - centre) * 0.2, 1e-5);
    std::printf("\ntongue %d:%d edges: RMHB (folds of the locked branch) %.10f and %.10f; CVODE phase-slip bisection "
                "(to 1e-5) %.6f and %.6f; differences %.1e and %.1e (%.1f s)\n",
                t.lock.p, t.lock.q, t.near_edge, t.far_edge, near, far, std::abs(near - t.near_edge),
                std::abs(far - t.far_edge), Seconds(t0));
  }
  std::printf("\nthe staircase by CVODE (w2/w = 1 - slips / 4000):\n");
  for (double w = 0.95; w <= 1.0501; w += 0.01) std::printf("  w = %.2f  w2/w = %.5f\n", w, 1 - Slips(w) / 4000.0);
}

void AsymmetricPendulum() {
  SolveSettings settings;  // defaults, as rmhb solve --continue: the first point's adaptive index set
  settings.default_torus_tol = SolveSettings::kDefaultTolerance;
  const PreparedSolve prepared = PrepareSolve(examples::LoadModelOrExample("asym-pendulum", {}), settings);
  ContinueOptions o;
  o.parameter = "x0";
  o.from = 0.1;
  o.to = 0.2;
  o.max_step = 0.004;  // ~40 points, every 10th validated
  o.harmonic_balance = prepared.options;
  const auto start = std::chrono::steady_clock::now();
  const BranchSummary b = ContinueModel(prepared.model, prepared.guess, o);
  std::printf("\n== 2. asymmetric pendulum in x0 = 0.1 -> 0.2 (%.1f s)\n%s\n", Seconds(start), b.FullReport().c_str());
  std::printf("%-10s %-20s %-20s %-9s %s\n", "x0", "w1", "w2", "outermost", "CVODE over t in [0, 2000]: max error, relative");
  for (size_t i = 0; i < b.continuation.points.size(); i += 10) {
    const ContinuationPoint& p = b.continuation.points[i];
    const Model here = WithParameters(prepared.model, {{"x0", p.parameter}});
    const auto v = ValidateOriginal(here, p.solution, 2000, 4001);
    const ValidationVerdict verdict = JudgeValidation(here, p.solution, v, 2000, 1e-8);
    std::printf("%-10.6g %-20.15g %-20.15g %-9.1e %.2e, %s\n", p.parameter, p.solution.frequencies()[0],
                p.solution.frequencies()[1], b.reports[i].outermost, v.max_error, verdict.Describe().c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::string part = argc > 1 ? argv[1] : "all";
  if (part == "all" || part == "vdp") ForcedVanDerPol();
  if (part == "all" || part == "pendulum") AsymmetricPendulum();
  return 0;
}

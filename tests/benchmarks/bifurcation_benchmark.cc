// Stability along a branch and its bifurcations, on demand:
//   build/tests/benchmarks/bifurcation_benchmark [stability|nlvib|all]
// - stability: the cost per point of Hill's method (QZ on the harmonic
//   balance Jacobian) and of the CVODE monodromy of the original equations
//   against the number of unknowns (the quadratic oscillator of the tests at
//   N = 10 ... 80, chains of 2 ... 8 forced cubic oscillators at N = 25),
//   and how far their multipliers are apart at the first point.
// - unilateral [N] [M]: NLvib's example 03 as written, max(x1 - 1, 0)
//   (tests/benchmarks/models/unilateral.yaml; default N = 21, M = 4096):
//   the branch, its bifurcations against shooting, every point against
//   CVODE with the contact switches located by root finding.
// - nlvib: NLvib's example 03 with its unilateral spring smoothed by tanh
//   (tests/benchmarks/models/unilateral-smooth.yaml, N = 30), Omega from 0.8
//   down to 0.5: the bifurcations located by continuation against the
//   brute-force shooting reference, every point against a CVODE trajectory,
//   the period-2T branch from the period doubling and the torus past the
//   Neimark-Sacker point, each validated against CVODE.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "rmhb/branch_switching.h"
#include "rmhb/pipeline/monodromy.h"
#include "tests/pipeline/shooting.h"

using namespace rmhb;

namespace {

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A chain of `n` cubic oscillators, the first forced: a model file a user
// would write, in a temporary folder.
std::string ChainModel(int n) {
  const std::string file = (std::filesystem::temp_directory_path() / ("rmhb-chain-" + std::to_string(n) + ".yaml")).string();
  std::ofstream out(file);
  out << "name: chain" << n << "\nvariables: [";
  for (int i = 1; i <= n; ++i) out << (i > 1 ? ", " : "") << "x" << i;
  out << "]\nparameters: {W: 0.5}\nequations:\n";
  for (int i = 1; i <= n; ++i) {
    out << "  - \"x" << i << "'' + 0.05*x" << i << "' + 2*x" << i << " + 0.5*x" << i << "^3";
    if (i > 1) out << " - x" << i - 1;
    if (i < n) out << " - x" << i + 1;
    out << " = " << (i == 1 ? "0.2*cos(W*t)" : "0") << "\"\n";
  }
  out << "frequencies: [W]\n";
  return file;
}

// One short trace with the given method; per-point stability cost.
void Row(const char* label, const std::string& file, const std::string& parameter, double from, double to,
         int order) {
  const Model model = LoadModel(file, {{parameter, from}});
  const ContinuationProblem problem = ModelContinuationProblem(
      [file, parameter](double v) { return LoadModel(file, {{parameter, v}}); }, parameter, from, to);
  double per_point[2] = {NAN, NAN};
  int unknowns = 0;
  std::string cross;
  for (int m = 0; m < 2; ++m) {
    ContinuationOptions options;
    options.harmonic_balance.order = order;
    options.max_points = 6;
    options.stability_method = m == 0 ? StabilityMethod::kHill : StabilityMethod::kMonodromy;
    options.max_hill_unknowns = 1 << 30;
    if (m == 0) {  // Hill's QZ beyond ~1500 unknowns takes minutes per point
      const HarmonicBasis basis = HarmonicBasis::Periodic(order);
      unknowns = model.problem.system.num_variables() * basis.num_coefficients();
      if (unknowns > 1500) continue;
    }
    const ContinuationSummary s = TraceBranch(problem, GuessAtOrder(model, order), options);
    per_point[m] = s.stability_seconds / std::max(1, s.hill_points + s.monodromy_points);
  }
  ContinuationOptions both;
  both.harmonic_balance.order = order;
  both.max_points = 2;
  both.max_cross_check_unknowns = 1500;
  const ContinuationSummary c = TraceBranch(problem, GuessAtOrder(model, order), both);
  std::printf("%-28s %4d %9d %14.2f %16.2f   %s\n", label, order, unknowns, 1e3 * per_point[0], 1e3 * per_point[1],
              c.stability_cross_check.c_str());
}

void StabilityCost() {
  std::printf("stability per point: Hill's QZ against the CVODE monodromy (rtol 1e-10)\n");
  std::printf("%-28s %4s %9s %14s %16s   %s\n", "model", "N", "unknowns", "Hill ms/point", "monodromy ms/pt",
              "first point, both");
  const std::string quadratic = std::string(RMHB_SOURCE_DIR) + "/tests/pipeline/models/quadratic-duffing.yaml";
  for (int order : {10, 20, 40, 80}) Row("quadratic oscillator (1 DOF)", quadratic, "w", 2.5, 2.3, order);
  for (int n : {2, 4, 8}) {
    const std::string label = "cubic chain, " + std::to_string(n) + " DOF";
    Row(label.c_str(), ChainModel(n), "W", 0.5, 0.55, 25);
  }
}

// NLvib's example 03, smoothed (unilateral-smooth.yaml, N = 30, the
// branches from the PD and NS points too) or as written with max()
// (unilateral.yaml: N and M given, every point against the event-located
// CVODE reference).
void NlvibExample03(const std::string& name, int order, int samples, bool branches) {
  const std::string file = std::string(RMHB_SOURCE_DIR) + "/tests/benchmarks/models/" + name + ".yaml";
  const Model model = LoadModel(file, {{"W", 0.8}});
  const ContinuationProblem problem =
      ModelContinuationProblem([file](double W) { return LoadModel(file, {{"W", W}}); }, "W", 0.8, 0.5);
  ContinuationOptions options;
  options.harmonic_balance.order = order;
  if (samples > 0) options.harmonic_balance.samples = {samples};
  auto start = std::chrono::steady_clock::now();
  const ContinuationSummary s = TraceBranch(problem, GuessAtOrder(model, order), options);
  const double seconds = Since(start);
  std::printf("\nNLvib example 03 (%s), N = %d, M = %d, Omega 0.8 -> 0.5\n%s\n", name.c_str(), order,
              samples, s.BriefReport().c_str());
  std::printf("trace %.2f s, stability %.2f s (%d Hill, %d monodromy)\n", seconds, s.stability_seconds, s.hill_points,
              s.monodromy_points);
  // Every point against CVODE over one period (event-located for max()).
  double worst = 0, sum = 0;
  std::string integrator;
  for (const ContinuationPoint& p : s.points) {
    const Model here = LoadModel(file, {{"W", p.parameter}});
    const double T = 2 * M_PI / p.parameter;
    const integrators::ValidationReport v = ValidateOriginal(here, p.solution, T, 201);
    const double e = v.ok ? JudgeValidation(here, p.solution, v, T, 1).relative_error : HUGE_VAL;
    worst = std::max(worst, e);
    sum += e;
    integrator = v.integrator;
  }
  std::printf("every point against %s over a period: max relative error %.1e, mean %.1e\n", integrator.c_str(),
              worst, sum / s.points.size());
  // The bifurcations against the shooting reference.
  Eigen::VectorXd y = model.state(s.points.front().solution, 0.0);
  for (const BifurcationPoint& b : s.bifurcations) {
    std::printf("  %s\n", b.Describe("W").c_str());
    if (b.type != BifurcationType::kPeriodDoubling && b.type != BifurcationType::kNeimarkSacker) continue;
    const bool pd = b.type == BifurcationType::kPeriodDoubling;
    const Model at = LoadModel(file, {{"W", b.parameter}});
    y = at.state(s.points[b.point].solution, 0.0);
    // A kink's truncation at N = 21 moves the crossing by up to ~1e-3: a
    // wider bracket when the narrow one holds none (not first: next to a
    // turning point the wide one reaches past the fold).
    const Eigen::VectorXd start = y;
    double reference = testing::ReferenceCrossing(at, b.parameter - 1e-4, b.parameter + 1e-4, pd, &y);
    if (std::isnan(reference) && model.original_switched)
      y = start, reference = testing::ReferenceCrossing(at, b.parameter - 3e-3, b.parameter + 3e-3, pd, &y);
    std::printf("    shooting reference W = %.12f: error %.1e\n", reference, b.parameter - reference);
  }
  for (const BifurcationPoint& b : s.bifurcations) {
    if (!branches) break;
    if (b.type == BifurcationType::kPeriodDoubling) {
      start = std::chrono::steady_clock::now();
      const DoubledBranch d = TraceDoubledBranch(problem, s, b, options);
      std::printf("period-2T branch from W = %.10f (%.2f s): %s\n", b.parameter, Since(start), d.message.c_str());
      if (!d.branch) continue;
      double doubled = 0;
      for (const ContinuationPoint& p : d.branch->points) {
        const Model here = LoadModel(file, {{"W", p.parameter}});
        const double T = 2 * 2 * M_PI / p.parameter;
        auto claimed = [&](double t) { return here.state(p.solution, t); };
        const integrators::ValidationReport v =
            integrators::ValidateTrajectory(here.original({p.parameter}), claimed, T, false, 201);
        doubled = std::max(doubled, v.ok ? v.max_error : HUGE_VAL);
      }
      std::printf("  every point against CVODE over 2T: max error %.1e\n", doubled);
    }
    if (b.type == BifurcationType::kNeimarkSacker)
      for (int order_new : {4, 8, 12}) {
        TorusOptions torus;
        torus.order_new = order_new;
        start = std::chrono::steady_clock::now();
        const TorusStart t = TorusFromNeimarkSacker(problem, s, b, options, torus);
        std::printf("|l| <= %d: %s (%.2f s)\n", order_new, t.BriefReport().c_str(), Since(start));
        if (!t.solved) continue;
        const Model here = LoadModel(file, {{"W", t.parameter}});
        const double t_end = 20 * 2 * M_PI / t.parameter;
        const integrators::ValidationReport v = ValidateTorus(here, *t.torus, t_end);
        std::printf("  torus against CVODE over 20 periods: %s\n",
                    JudgeValidation(here, *t.torus, v, t_end, 1e-6).Describe().c_str());
      }
  }
}

// ---- NLvib side by side on its example 03 (tests/benchmarks/peers/unilateral_bench) ----
// NLvib's layout: X = [Q0; Qc1; Qs1; ...], each block over the two masses.
const std::string kUnilateral = std::string(RMHB_SOURCE_DIR) + "/tests/benchmarks/models/unilateral.yaml";

// The branch at order N and M samples; every `stride`-th point as a line
// "Om X" with X the PREVIOUS point's solution (the start both tools get),
// or with `own`, the point's own solution on the branch (the start of the
// refinement at higher orders, which thus exists also where the fixed-Omega
// solve from the previous point fails: next to the turning points).
void UnilateralPoints(int order, int samples, int stride, bool own) {
  const Model model = LoadModel(kUnilateral, {{"W", 0.8}});
  const ContinuationProblem problem =
      ModelContinuationProblem([](double W) { return LoadModel(kUnilateral, {{"W", W}}); }, "W", 0.8, 0.5);
  ContinuationOptions options;
  options.harmonic_balance.order = order;
  options.harmonic_balance.samples = {samples};
  options.stability = false;
  const ContinuationSummary s = TraceBranch(problem, GuessAtOrder(model, order), options);
  const int x1 = model.problem.system.IndexOf("x1"), x2 = model.problem.system.IndexOf("x2");
  for (size_t i = stride; i < s.points.size(); i += stride) {
    const Eigen::MatrixXd& c = s.points[own ? i : i - 1].solution.coefficients();
    std::printf("%.17g", s.points[i].parameter);
    for (int k = 0; k < c.cols(); ++k) std::printf(" %.17g %.17g", c(x1, k), c(x2, k));
    std::printf("\n");
  }
}

// x1, x2 from NLvib's X, their derivatives for the chain variables.
HarmonicSolution FromNlvib(const Model& model, double W, const std::vector<double>& X) {
  const int C = static_cast<int>(X.size()) / 2;
  const HarmonicBasis basis = HarmonicBasis::Periodic((C - 1) / 2);
  const PolynomialSystem& sys = model.problem.system;
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(sys.num_variables(), C);
  for (int m = 0; m < 2; ++m) {
    const int x = sys.IndexOf(m == 0 ? "x1" : "x2"), v = sys.IndexOf(m == 0 ? "x1_d1" : "x2_d1");
    for (int k = 0; k < C; ++k) c(x, k) = X[2 * k + m];
    for (int h = 1; 2 * h < C; ++h) {
      c(v, 2 * h - 1) = h * W * c(x, 2 * h);
      c(v, 2 * h) = -h * W * c(x, 2 * h - 1);
    }
  }
  return HarmonicSolution(basis, {W}, c, sys.variables());
}

double AgainstCvode(const Model& here, const HarmonicSolution& s) {
  const double T = 2 * M_PI / s.frequencies()[0];
  const integrators::ValidationReport v = ValidateOriginal(here, s, T, 401);
  return v.ok ? JudgeValidation(here, s, v, T, 1).relative_error : HUGE_VAL;
}

// Each point of `points` (UnilateralPoints) solved by rmhb from the same
// start at the same N and M, timed (median), and both answers (NLvib's from
// `nlvib`: "Om seconds flag X") against CVODE with the contact located; then
// rmhb at higher orders from the branch's own point (`own`).
void UnilateralCompare(int order, int samples, const char* points, const char* nlvib, const char* own) {
  std::ifstream p(points), q(nlvib), o(own);
  std::printf("NLvib example 03 as written (max), H = N = %d harmonics, %d samples, both from the previous "
              "point's solution\n",
              order, samples);
  std::printf("%-10s %-9s %-9s %-11s %-11s %-8s | rmhb at 4N: %-7s %-9s | at 16N: %-7s %-9s | at 128N, Krylov: %-7s "
              "%-9s\n",
              "Omega", "rmhb ms", "NLvib ms", "rmhb error", "NLvib error", "max|x1|", "ms", "error", "ms", "error", "ms",
              "error");
  std::string a, b, c;
  while (std::getline(p, a) && std::getline(q, b) && std::getline(o, c)) {
    std::istringstream pa(a), qb(b), oc(c);
    double W, Wn, Wo, nlvib_seconds, flag;
    pa >> W;
    qb >> Wn >> nlvib_seconds >> flag;
    oc >> Wo;
    std::vector<double> start, theirs, branch;
    for (double v; pa >> v;) start.push_back(v);
    for (double v; qb >> v;) theirs.push_back(v);
    for (double v; oc >> v;) branch.push_back(v);
    const Model here = LoadModel(kUnilateral, {{"W", W}});
    HarmonicBalanceOptions options;
    options.order = order;
    options.samples = {samples};
    options.order_continuation = false;
    const HarmonicSolution guess = FromNlvib(here, W, start);
    std::vector<double> times;
    HarmonicBalanceSummary s;
    for (int r = 0; r < 7; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      s = SolveHarmonicBalance(here.problem, guess, options);
      times.push_back(Since(t0));
    }
    std::sort(times.begin(), times.end());
    const double mine = s.usable() ? AgainstCvode(here, *s.solution) : HUGE_VAL;
    const double other = flag > 0 ? AgainstCvode(here, FromNlvib(here, W, theirs)) : HUGE_VAL;
    double amplitude = 0;
    if (s.solution)
      for (int i = 0; i < 200; ++i) amplitude = std::max(amplitude, std::abs(s.solution->Value(0, 0.0314 * i / W)));
    std::printf("%-10.6f %-9.2f %-9.2f %-11.2e %-11.2e %-8.4f", W, 1e3 * times[3], 1e3 * nlvib_seconds, mine, other,
                amplitude);
    // Higher orders from the branch's point, M = 32 x (4N, 16N,
    // 128N) rounded up to a power of two; 128N (2688 harmonics, 10754
    // unknowns) by Newton-Krylov, where a dense LU would need 0.9 GiB and
    // minutes per factorisation.
    for (int factor : {4, 16, 128}) {
      HarmonicBalanceOptions high;
      high.order = factor * order;
      high.samples = {NonSmoothSamples(factor * order, 32)};
      high.order_continuation = false;
      if (factor > 16) high.solver.linear_solver = LinearSolver::kKrylov;
      const auto t0 = std::chrono::steady_clock::now();
      const HarmonicBalanceSummary h = SolveHarmonicBalance(here.problem, FromNlvib(here, W, branch), high);
      const double seconds = Since(t0);
      std::printf(" | %-18.1f %-9.2e", 1e3 * seconds, h.usable() ? AgainstCvode(here, *h.solution) : HUGE_VAL);
    }
    std::printf("\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "all";
  if (what == "stability" || what == "all") StabilityCost();
  if (what == "nlvib" || what == "all") NlvibExample03("unilateral-smooth", 30, 0, true);
  // build/tests/benchmarks/bifurcation_benchmark unilateral [N] [M]
  if (what == "unilateral-points")
    UnilateralPoints(std::atoi(argv[2]), std::atoi(argv[3]), std::atoi(argv[4]), argc > 5 && std::string(argv[5]) == "own");
  if (what == "unilateral-compare")
    UnilateralCompare(std::atoi(argv[2]), std::atoi(argv[3]), argv[4], argv[5], argv[6]);
  if (what == "unilateral" || what == "all")
    NlvibExample03("unilateral", argc > 2 ? std::atoi(argv[2]) : 21, argc > 3 ? std::atoi(argv[3]) : 4096, false);
  return 0;
}

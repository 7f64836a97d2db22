#include "rmhb/harmonic_balance.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "rmhb/collocation_residual.h"
#include "rmhb/symmetry.h"
#include "rmhb/truncation_estimate.h"

namespace rmhb {

std::string HarmonicBalanceOptions::IsValid() const {
  if (order < 1) return "order must be >= 1 (got " + std::to_string(order) + ")";
  if (!(max_jacobian_bytes > 0)) return "max_jacobian_bytes must be > 0";
  if (!(max_gcd_excess > 0)) return "max_gcd_excess must be > 0";
  if (!(tolerance >= 0) || !std::isfinite(tolerance))
    return "tolerance must be finite and >= 0 (0: fixed order)";
  if (tolerance > 0 && max_order < order)
    return "max_order (" + std::to_string(max_order) + ") is below order (" +
           std::to_string(order) + ")";
  for (int m : samples)
    if (m < 1) return "samples must be >= 1 (got " + std::to_string(m) + ")";
  if (!(min_frequency_ratio >= 0) || !(min_frequency_ratio < 1))
    return "min_frequency_ratio must be in [0, 1)";
  if (std::string why = definition_check.IsValid(); !why.empty()) return "definition_check: " + why;
  return solver.IsValid();
}

const char* ToString(TargetQuantity quantity) {
  return quantity == TargetQuantity::kFrequency ? "frequency" : "state";
}

TargetQuantity ParseTargetQuantity(const std::string& name) {
  if (name == "state") return TargetQuantity::kState;
  if (name == "frequency") return TargetQuantity::kFrequency;
  throw std::invalid_argument("target quantity must be state or frequency (got '" + name + "')");
}

HarmonicBasis MakeBasis(int num_bases, const HarmonicBalanceOptions& options) {
  if (num_bases == 1) return HarmonicBasis::Periodic(options.order);
  if (options.basis_for_order) {
    HarmonicBasis basis = options.basis_for_order(options.order);
    if (basis.num_bases() != num_bases)
      throw std::invalid_argument("basis_for_order gave a basis over " +
                                  std::to_string(basis.num_bases()) + " bases for a problem with " +
                                  std::to_string(num_bases));
    return basis;
  }
  return options.shape == BasisShape::kBox ? HarmonicBasis::Box(num_bases, options.order)
                                           : HarmonicBasis::Diamond(num_bases, options.order);
}

namespace {

// Points k of Z^d with |k|_1 <= p: the coefficients per variable of the
// diamond basis (each harmonic but k = 0 carries a cosine and a sine, and
// k, -k are one harmonic). sum_j 2^j C(d, j) C(p, j).
double DiamondCoefficients(int d, int p) {
  double total = 0, cd = 1, cp = 1;
  for (int j = 0; j <= std::min(d, p); ++j) {
    total += std::ldexp(cd * cp, j);
    cd = cd * (d - j) / (j + 1);
    cp = cp * (p - j) / (j + 1);
  }
  return total;
}

double CoefficientsPerVariable(int d, const HarmonicBalanceOptions& options) {
  const int p = options.order;
  if (d == 1) return 2.0 * p + 1;
  // A problem-specific basis has no formula; build it while that is cheap
  // (it fits in its box), else size it like the diamond.
  if (options.basis_for_order && std::pow(2.0 * p + 1, d) <= 4e6)
    return MakeBasis(d, options).num_coefficients();
  if (options.shape == BasisShape::kBox && !options.basis_for_order) return std::pow(2.0 * p + 1, d);
  return DiamondCoefficients(d, p);
}

std::string Gib(double bytes) {
  std::ostringstream out;
  out.precision(3);
  out << bytes / double(1L << 30) << " GiB";
  return out.str();
}

// Pointwise equations alias at every M. The solution's residual on a grid
// twice as fine (max|F| relative to max(1, max|coefficient|)) measures how
// much of it rests on the folded harmonics: at the truncation level for a
// solution of the equations, O(1) for one that exists only at the samples.
// False (and non-physical) above options.definition_check.floor.
// The grid twice as fine is the solve's grid and its copies shifted by half
// a step along each angle (Sampling::half_step): its projection is the mean
// of theirs, and they use the solve's tables and plans, where a grid of 2M
// made its own (a third of a first solve's time, issue 14).
bool AliasCheck(const HarmonicBalanceProblem& problem, const HarmonicBalanceOptions& options,
                HarmonicBalanceSummary* summary) {
  const HarmonicSolution& s = *summary->solution;
  const std::vector<int>& grid = summary->samples;
  std::vector<int> fine;
  long total = 1;
  for (int m : grid) fine.push_back(2 * m), total *= fine.back();
  if (total > options.max_samples) return true;  // not checked: too large a grid
  const int copies = 1 << grid.size();
  Eigen::VectorXd F, sum;
  for (int copy = 0; copy < copies; ++copy) {
    Sampling sampling = grid.size() == 1 ? Sampling::Uniform(grid[0]) : Sampling::Torus(grid);
    for (size_t d = 0; d < grid.size(); ++d) sampling.half_step.push_back((copy >> d) & 1);
    CollocationResidual residual(problem, s.basis(), sampling, options.condense_definitions);
    residual.Evaluate(residual.Pack(s.coefficients(), s.frequencies()), &F, nullptr);
    if (copy == 0) sum = F;
    else sum += F;
  }
  F = sum / copies;
  const double scale = std::max(1.0, s.coefficients().cwiseAbs().maxCoeff());
  summary->alias_residual = F.size() ? F.cwiseAbs().maxCoeff() / scale : 0.0;
  summary->alias_check_samples = fine;
  summary->alias_tolerance = problem.system.HasNonSmooth() ? kNonSmoothAliasFloor : options.definition_check.floor;
  if (summary->alias_residual <= summary->alias_tolerance) return true;
  std::ostringstream why;
  why.precision(3);
  why << "the residual on " << total << " samples (twice the solve's) is " << summary->alias_residual
      << " (relative) > " << summary->alias_tolerance
      << ": the solution holds at the samples only (aliasing of the pointwise equations)";
  summary->physical = false;
  summary->non_physical = why.str();
  return false;
}

// An autonomous orbit of frequency w written on the base w/g (every harmonic
// off the multiples of g zero) solves the equations as well as on w: a
// converged solve can land there (the pendulum from a guess of zero harmonics
// finds w/3), and its "frequency" is then g times too small. The support's
// gcd says so; harmonics below kSupportFloor of the largest do not count.
constexpr double kSupportFloor = 1e-9;

bool CheckFundamental(const HarmonicBalanceProblem& problem, HarmonicBalanceSummary* summary) {
  const HarmonicSolution& s = *summary->solution;
  if (s.frequencies().size() != 1 || problem.num_unknown_frequencies() != 1) return true;
  const Eigen::MatrixXd& c = s.coefficients();
  const HarmonicBasis& basis = s.basis();
  Eigen::VectorXd size(basis.size());
  size(0) = 0;
  for (int k = 1; k < basis.size(); ++k)
    size(k) = std::max(c.col(2 * k - 1).cwiseAbs().maxCoeff(), c.col(2 * k).cwiseAbs().maxCoeff());
  int g = 0;
  for (int k = 1; k < basis.size(); ++k)
    if (size(k) > kSupportFloor * size.maxCoeff()) g = std::gcd(g, std::abs(basis.harmonic(k)[0]));
  if (g <= 1) return true;
  std::ostringstream why;
  why.precision(15);
  why << "every harmonic off the multiples of " << g << " is below " << kSupportFloor
      << " of the largest: the orbit repeats " << g << " times per period, its frequency is " << g
      << " w = " << g * s.frequencies()[0] << ", not the w = " << s.frequencies()[0] << " it converged to";
  summary->physical = false;
  summary->non_physical = why.str();
  summary->repeats = g;
  return false;
}

// Sets summary->physical: a converged solution whose unknown frequency
// collapsed (Newton on a singular system may slide to w = 0, a constant) or
// whose auxiliaries are not their definitions is no oscillation of the model.
void CheckPhysical(const HarmonicBalanceProblem& problem, const HarmonicBalanceOptions& options,
                   HarmonicBalanceSummary* summary) {
  if (!options.check_physical || !summary->converged() || !summary->solution) return;
  const std::vector<double>& w = summary->solution->frequencies();
  for (size_t b = 0; b < w.size(); ++b) {
    if (problem.unknown_frequency.empty() || !problem.unknown_frequency[b]) continue;
    const double guess = std::abs(problem.frequencies[b]);
    if (!(w[b] > options.min_frequency_ratio * guess) || !(w[b] > 0)) {
      std::ostringstream why;
      why.precision(6);
      why << "unknown frequency w" << b + 1 << " converged to " << w[b] << " (guess "
          << problem.frequencies[b] << "): "
          << (w[b] <= 0 ? "not a positive frequency" : "a vanishing frequency")
          << ", the solution is a constant, not an oscillation";
      summary->physical = false;
      summary->non_physical = why.str();
      return;
    }
  }
  // An equilibrium (every harmonic but the mean zero) solves the equations of
  // an autonomous problem at ANY frequency: the unknown frequency is then
  // undetermined and the result no oscillation (Newton on the pendulum's
  // scheme 3, which pins no amplitude, can land there).
  if (problem.num_unknown_frequencies() > 0) {
    const Eigen::MatrixXd& c = summary->solution->coefficients();
    const double scale = std::max(1.0, c.cwiseAbs().maxCoeff());
    if (c.cols() > 1 && c.rightCols(c.cols() - 1).cwiseAbs().maxCoeff() <= 1e-10 * scale) {
      summary->physical = false;
      summary->non_physical =
          "every harmonic but the mean is zero (below 1e-10): an equilibrium, not an oscillation; "
          "the unknown frequency is undetermined";
      return;
    }
  }
  if (!CheckFundamental(problem, summary)) return;
  if (problem.system.HasPointwise() && !AliasCheck(problem, options, summary)) return;
  // Without auxiliaries every variable is a state: nothing to compare.
  const std::vector<Variable>& variables = problem.system.variables();
  if (!problem.definitions ||
      std::none_of(variables.begin(), variables.end(),
                   [](const Variable& v) { return v.role == VariableRole::kAuxiliary; }))
    return;
  summary->definition_check =
      CheckDefinitions(*summary->solution, problem.definitions, summary->samples, options.definition_check);
  if (const DefinitionCheck& c = *summary->definition_check; !c.physical) {
    std::ostringstream why;
    why.precision(3);
    why << "auxiliary " << c.worst_variable << " is " << c.error
        << " (relative) off its definition";
    if (std::isfinite(c.worst_time)) why << " at t = " << c.worst_time;
    why << " (tolerance " << c.tolerance << ", " << c.points
        << " points between the samples): a wrong root of the recast or aliasing";
    summary->physical = false;
    summary->non_physical = why.str();
  }
}

}  // namespace

JacobianSize DenseJacobianSize(const HarmonicBalanceProblem& problem,
                               const HarmonicBalanceOptions& options) {
  const double c = CoefficientsPerVariable(static_cast<int>(problem.frequencies.size()), options);
  JacobianSize size;
  size.columns = problem.system.num_variables() * c + problem.num_unknown_frequencies();
  // A pinned equation trades its constant row for a condition (METHOD.md s.4).
  size.rows = problem.system.num_equations() * c + double(problem.conditions.size());
  for (const auto& e : problem.system.equations()) size.rows -= e.balance_constant ? 0 : 1;
  return size;
}

void CheckJacobianSize(const HarmonicBalanceProblem& problem, const HarmonicBalanceOptions& options) {
  const JacobianSize size = DenseJacobianSize(problem, options);
  if (size.bytes() <= options.max_jacobian_bytes) return;
  // Asked for explicitly, the sparse and Krylov solvers never form the
  // dense J (METHOD.md s.17); kAuto keeps the limit as the guard against an
  // order typed by mistake.
  const LinearSolver solver = options.solver.linear_solver;
  if (solver == LinearSolver::kSparse || solver == LinearSolver::kKrylov) return;
  std::ostringstream msg;
  msg.precision(15);
  msg << "order " << options.order << " needs a dense Jacobian of " << size.rows << " x "
      << size.columns << " doubles (" << Gib(size.bytes()) << "); the limit is "
      << Gib(options.max_jacobian_bytes)
      << " (set by HarmonicBalanceOptions::max_jacobian_bytes, --max-jacobian-gib)";
  throw std::invalid_argument(msg.str());
}

std::string HarmonicBalanceSummary::BriefReport() const {
  std::ostringstream out;
  out << ToString(rule) << " order " << order << ", samples";
  for (int m : samples) out << " " << m;
  // Pointwise (original) equations have no alias-free count (written as 0).
  const bool pointwise = !alias_free_samples.empty() && alias_free_samples[0] == 0;
  out << (alias_free ? " (alias-free)" : pointwise ? " (original equations, pointwise)" : " (ALIASED)") << ": "
      << ToString(solver.status)
      << " in " << solver.iterations << " iterations, max|F| " << solver.final_residual << ", "
      << seconds * 1e3 << " ms";
  if (!physical) out << "; NON-PHYSICAL: " << non_physical;
  return out.str();
}

std::string HarmonicBalanceSummary::FullReport() const {
  std::ostringstream out;
  out.precision(16);
  out << "Harmonic balance (" << ToString(rule) << "), degree phi = " << degree << ", order "
      << order << "\n";
  out << "  sampling: " << sampling << "; alias-free minimum";
  for (int m : alias_free_samples) out << " " << m;
  out << (alias_free ? " (alias-free: equivalent to classical HB)"
                     : " (below the bound: aliasing, non-physical solutions possible)")
      << "\n";
  out << "  " << solver.FullReport();
  if (!physical) out << "  NON-PHYSICAL: " << non_physical << "\n";
  else if (definition_check) out << "  definitions: " << definition_check->Report() << "\n";
  if (truncation_estimate >= 0) {
    out << "  order selection: orders";
    for (int o : orders_tried) out << " " << o;
    out << "; target " << tolerance << " (" << ToString(tolerance_quantity) << "); estimated error: state "
        << state_estimate;
    if (frequency_estimate >= 0) out << ", frequency " << frequency_estimate;
    out << (estimate_calibrated ? "" : " (tail only)");
    if (sampling_estimate >= 0) out << "; sampling " << sampling_estimate << " of it (half the samples)";
    out << "\n";
  }
  if (solution) {
    out << "  frequencies:";
    for (double w : solution->frequencies()) out << " " << w;
    out << "\n";
  }
  return out.str();
}

namespace {

// On `given_basis` when set, else on the options' basis at their order.
HarmonicBalanceSummary SolveAtOrder(const HarmonicBalanceProblem& problem,
                                    const HarmonicSolution& guess,
                                    const HarmonicBalanceOptions& options,
                                    const HarmonicBasis* given_basis = nullptr) {
  HarmonicBalanceSummary summary;
  summary.order = given_basis ? given_basis->order() : options.order;
  summary.rule = options.rule;
  summary.degree = problem.system.Degree();
  const int d = static_cast<int>(problem.frequencies.size());
  const HarmonicBasis basis = given_basis ? *given_basis : MakeBasis(d, options);
  summary.samples = SamplesForRule(problem.system, basis, options.rule, &summary.alias_free_samples);
  if (!options.samples.empty()) {
    if (static_cast<int>(options.samples.size()) != d)
      throw std::invalid_argument("give one sample count per base frequency");
    summary.samples = options.samples;
  }
  Sampling sampling = d == 1 ? Sampling::Uniform(summary.samples[0])
                             : Sampling::Torus(summary.samples);
  if (d > 1 && options.quasi_periodic_sampling == QuasiPeriodicSampling::kGcd) {
    // One angle phi over 2 pi / gcd: harmonic k lands on r.k; the alias bound
    // is Theorem 1's on that 1-D spectrum (Theorem 2).
    const std::vector<int> r =
        RationalRatios(problem.frequencies, options.gcd_tolerance, options.max_samples);
    std::string ratios;
    for (int b = 0; b < d; ++b) ratios += (b ? ":" : "") + std::to_string(r[b]);
    // Harmonics k with equal |r.k| are one frequency over the common period:
    // the basis crosses a resonance of the ratio (5 w1 - 3 w2 = 0 for 3:5)
    // and the GCD rule cannot tell their coefficients apart.
    long reach = 0, forcing = 0;
    std::map<long, int> seen;
    for (int k = 0; k < basis.size(); ++k) {
      long v = 0;
      for (int b = 0; b < d; ++b) v += long(r[b]) * basis.harmonic(k)[b];
      reach = std::max(reach, std::labs(v));
      auto [it, fresh] = seen.emplace(std::labs(v), k);
      if (!fresh) {
        auto name = [&](int i) {
          std::string n = "(";
          for (int b = 0; b < d; ++b) n += (b ? "," : "") + std::to_string(basis.harmonic(i)[b]);
          return n + ")";
        };
        throw std::invalid_argument("GCD rule: harmonics " + name(it->second) + " and " + name(k) +
                                    " have the same frequency for ratios " + ratios +
                                    "; the basis reaches a resonance of the ratio, use the torus "
                                    "grid or a lower order");
      }
    }
    for (int b = 0; b < d; ++b) forcing += long(r[b]) * problem.system.ForcingReach(b);
    const long needed = (summary.degree + 1) * reach + forcing + 1;
    long torus = 1;
    for (int m : summary.samples) torus *= m;
    if (needed > options.max_samples)
      throw std::invalid_argument(
          "GCD rule needs " + std::to_string(needed) + " samples (ratios " + ratios +
          "), over the limit of " + std::to_string(options.max_samples) + "; use the torus grid");
    if (double(needed) > options.max_gcd_excess * double(torus)) {
      std::ostringstream msg;
      msg << "GCD rule needs " << needed << " samples (ratios " << ratios << "), "
          << needed / torus << " times the torus grid's " << torus << " (limit "
          << options.max_gcd_excess << "x); use the torus grid";
      throw std::invalid_argument(msg.str());
    }
    const int m = options.samples.empty() ? FftFriendlySize(static_cast<int>(needed)) : summary.samples[0];
    summary.alias_free_samples = {static_cast<int>(needed)};
    summary.samples = {m};
    summary.alias_free = m >= needed;
    sampling = Sampling::Gcd(m, r);
  }
  long total = 1;
  for (int m : summary.samples) total *= m;
  if (total > options.max_samples)
    throw std::invalid_argument("the sampling needs " + std::to_string(total) +
                                " samples, over the limit of " + std::to_string(options.max_samples));
  for (size_t b = 0; b < summary.samples.size(); ++b)
    summary.alias_free = summary.alias_free && summary.samples[b] >= summary.alias_free_samples[b];
  // Pointwise (original) equations alias at any M: checked after the solve
  // on a finer grid instead (AliasCheck).
  const bool pointwise = problem.system.HasPointwise();
  if (pointwise) summary.alias_free = false;
  if (!summary.alias_free && !pointwise && !options.allow_aliasing && options.rule != SamplingRule::kHdhb)
    throw std::invalid_argument(
        "samples below the alias-free bound (" + std::to_string(summary.alias_free_samples[0]) +
        "); aliasing gives non-physical solutions. Use the hdhb method or allow aliasing explicitly");
  summary.sampling = sampling.description;

  CollocationResidual residual(problem, basis, sampling, options.condense_definitions);
  std::vector<double> w = guess.frequencies();
  for (int b = 0; b < d; ++b)
    if (problem.unknown_frequency.empty() || !problem.unknown_frequency[b])
      w[b] = problem.frequencies[b];
  const HarmonicSolution start = guess.OnBasis(basis);
  Eigen::VectorXd x = residual.Pack(start.coefficients(), w);
  summary.solver = SolveNonlinear(residual, &x, options.solver);
  Eigen::MatrixXd coefficients;
  residual.Unpack(x, &coefficients, &w);
  summary.solution.emplace(basis, w, coefficients, problem.system.variables());
  return summary;
}

// The guess's own resolution: the highest level |k|_1 it holds above 1e-8
// of its variable's scale (at most its basis's order). A model file's
// one-harmonic guess projected on the start order's basis holds its
// auxiliaries' whole spectra (sin(1.5 cos t): J_k(1.5), 7e-11 at k = 12);
// a coarse order that drops what lies below 1e-8 keeps the guess's worth
// as a start, and the next order's Newton step restores it.
int GuessResolution(const HarmonicSolution& guess) {
  const std::vector<double> size = HarmonicSizes(guess);
  int level = 0;
  for (int k = 0; k < guess.basis().size(); ++k) {
    if (!(size[k] > 1e-8)) continue;
    int l = 0;
    for (int m : guess.basis().harmonic(k)) l += std::abs(m);
    level = std::max(level, l);
  }
  return std::min(level, guess.basis().order());
}

// A coarse level is close enough to the final order when what it leaves out
// is small: its outermost two harmonics (two: a half-wave symmetric spectrum
// has an empty layer at every even order), relative to each variable's
// largest coefficient, extrapolated geometrically with their ratio to the two
// before, sum to at most this. The final order's Newton then starts within
// about that distance and converges in two or three steps, so finer coarse
// levels cost more than they save (the relativistic oscillator at N = 55:
// 13 leaves ~2e-4 out, 13 -> 55 in 0.28 ms, 13 -> 27 -> 55 in 0.31 ms). A
// slowly decaying spectrum (a relaxation oscillation) extrapolates to much
// more and keeps every level. One base only.
constexpr double kCoarseRemainderEnough = 1e-3;

bool CloseEnough(const HarmonicSolution& coarse) {
  if (coarse.basis().num_bases() != 1 || coarse.basis().size() < 5) return false;
  const std::vector<double> size = HarmonicSizes(coarse);
  const size_t K = size.size();
  const double tail = std::max(size[K - 1], size[K - 2]), before = std::max(size[K - 3], size[K - 4]);
  if (!(before > 0) || !(tail < before)) return false;
  const double ratio = tail / before;  // per two harmonics
  return tail * ratio / (1 - ratio) <= kCoarseRemainderEnough;
}

// `converged_below`, when given, receives the last coarse solution that
// converged (order selection calibrates its estimate on it).
HarmonicBalanceSummary SolveWithContinuation(const HarmonicBalanceProblem& problem,
                                             const HarmonicSolution& initial_guess,
                                             const HarmonicBalanceOptions& options,
                                             std::optional<HarmonicSolution>* converged_below = nullptr) {
  HarmonicSolution guess = initial_guess;
  // Warm start through coarser orders: cheap solves that bring the guess into
  // the quadratic convergence region of the large system.
  if (options.order_continuation && options.samples.empty() && options.rule == SamplingRule::kRhb) {
    std::vector<int> orders;
    // Orders at or below the guess's own resolution would only truncate it.
    for (int o = options.order / 2, own = GuessResolution(initial_guess); o >= 8 && o > own; o /= 2)
      orders.insert(orders.begin(), o);
    for (int o : orders) {
      HarmonicBalanceOptions coarse = options;
      coarse.order = o;
      coarse.order_continuation = false;
      coarse.solver.acceptable_residual = 1e300;  // a truncated solve is only a guess
      coarse.solver.report_condition = false;     // nor is its Jacobian's condition read
      // Nor worth a Levenberg-Marquardt crawl when Newton fails on it (near
      // the pendulum's separatrix that crawl was most of the time).
      if (coarse.solver.method == SolverMethod::kAuto) coarse.solver.method = SolverMethod::kNewton;
      coarse.solver.step_tolerance = std::max(options.solver.step_tolerance, 1e-10);
      HarmonicBalanceSummary s = SolveAtOrder(problem, guess, coarse);
      if (s.solver.status == SolverStatus::kConverged ||
          s.solver.status == SolverStatus::kNoConvergence)
        if (s.solution && s.solver.final_residual < s.solver.initial_residual)
          guess = *s.solution;
      // Converged (step below 1e-10: Newton's next error ~1e-20): the coarse
      // order's own solution, however large its truncation.
      if (converged_below && s.converged() && s.solution) *converged_below = s.solution;
      // A caller that asked for the finest converged level gets every level.
      if (!converged_below && s.converged() && s.solution && CloseEnough(*s.solution)) break;
    }
  }
  return SolveAtOrder(problem, guess, options);
}

// The estimate of the quantity the tolerance is on (METHOD.md s.8): the
// frequency only when the problem has an unknown one and it was asked for.
double Targeted(const HarmonicBalanceProblem& problem, const HarmonicBalanceOptions& options,
                const TruncationEstimate& e) {
  return options.tolerance_quantity == TargetQuantity::kFrequency && problem.num_unknown_frequencies() > 0
             ? e.frequency
             : e.state;
}

void Record(const HarmonicBalanceProblem& problem, const HarmonicBalanceOptions& options,
            const TruncationEstimate& e, HarmonicBalanceSummary* s) {
  s->truncation_estimate = Targeted(problem, options, e);
  s->state_estimate = e.state;
  s->frequency_estimate = problem.num_unknown_frequencies() > 0 ? e.frequency : -1;
  s->estimate_calibrated = e.calibrated;
  s->tolerance = options.tolerance;
  s->tolerance_quantity = options.tolerance_quantity;
}

// The next order: where the fitted decay puts the estimate at a quarter of the
// tolerance, in steps of at least one (p + 1 for several bases, N + N/8 for
// one) and at most a factor 1.5 for one base (p + 2 for several): small
// steps, so that the solves before the last cost at most about as much as it
// (sum of (1/1.5^3)^i ~ 1.4). The step may always reach `reach` (the
// requested start order, from the half-order probe of SelectOrder). An
// algebraic decay (a non-smooth model) needs orders tens of times the start
// for a tight target, and its power law extrapolates far: steps up to 2x.
int NextOrder(int order, int bases, const TruncationEstimate& e, double tolerance, int reach) {
  // Half for an algebraic decay: its estimate extrapolates the tail's
  // N^(1 - p), and the error falls faster (N^-2.2 where the tail gave N^-2 on
  // NLvib's example 03), so the margin is in the extrapolation already.
  const double aim = (e.model == DecayModel::kAlgebraic ? 0.5 : 0.25) * tolerance;
  const int least = bases == 1 ? order + std::max(1, order / 8) : order + 1;
  const int factor = e.model == DecayModel::kAlgebraic ? 4 : 3;
  const int most = std::max(reach, bases == 1 ? std::max(least, (factor * order + 1) / 2) : order + 2);
  const int level = TruncationEstimate{e}.PredictLevel(aim);
  if (level < 0) return most;
  // Orders and levels coincide for the standard shapes; a custom index set
  // moves by the same number of levels.
  return std::clamp(order + (level - e.top_level), least, most);
}

// Adaptive enrichment (METHOD.md s.8): the harmonics next to every
// coefficient above `threshold` (steps |d|_1 <= 2, so that a spectrum with
// one parity still connects), extended along d while the ratio to the
// inner neighbour k - d predicts sizes above the threshold (up to 6 steps:
// a slow beat spreads the spectrum far along one direction). At most as
// many as the basis holds, the largest predicted first: the set at most
// doubles per round.
std::vector<std::vector<int>> Enrich(const HarmonicSolution& s, double threshold) {
  const HarmonicBasis& basis = s.basis();
  const int d = basis.num_bases();
  const std::vector<double> size = HarmonicSizes(s);
  std::map<std::vector<int>, int> index;
  for (int k = 0; k < basis.size(); ++k) {
    index[basis.harmonic(k)] = k;
    std::vector<int> neg = basis.harmonic(k);
    for (int& v : neg) v = -v;
    index[neg] = k;
  }
  const std::vector<std::vector<int>> steps = NeighbourSteps(d);
  std::map<std::vector<int>, double> candidates;  // canonical sign -> predicted size
  auto add = [&](std::vector<int> k, double predicted) {
    bool zero = true;
    for (int v : k) zero = zero && v == 0;
    if (zero || index.count(k)) return;
    const auto first = std::find_if(k.begin(), k.end(), [](int v) { return v != 0; });
    if (*first < 0)
      for (int& v : k) v = -v;
    double& best = candidates[k];
    best = std::max(best, predicted);
  };
  for (int k = 1; k < basis.size(); ++k) {
    if (!(size[k] > threshold)) continue;
    for (const auto& step : steps) {
      std::vector<int> inner = basis.harmonic(k), next = inner;
      for (int i = 0; i < d; ++i) inner[i] -= step[i], next[i] += step[i];
      const auto in = index.find(inner);
      const double ratio = in != index.end() && size[in->second] > 0 ? size[k] / size[in->second] : 1;
      int layers = 1;
      if (ratio < 0.9) layers = std::clamp(int(std::ceil(std::log(threshold / size[k]) / std::log(ratio))), 1, 6);
      double predicted = size[k];
      for (int l = 1; l <= layers; ++l) {
        predicted *= std::min(ratio, 1.0);
        add(next, predicted);
        for (int i = 0; i < d; ++i) next[i] += step[i];
      }
    }
  }
  std::vector<std::pair<double, std::vector<int>>> ranked;
  for (auto& [k, predicted] : candidates) ranked.push_back({predicted, k});
  std::sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  if (static_cast<int>(ranked.size()) > basis.size()) ranked.resize(basis.size());
  std::vector<std::vector<int>> out;
  for (auto& r : ranked) out.push_back(std::move(r.second));
  return out;
}

int Reach(const HarmonicBasis& basis) {
  int top = 0;
  for (const auto& k : basis.harmonics()) {
    int l = 0;
    for (int m : k) l += std::abs(m);
    top = std::max(top, l);
  }
  return top;
}

// The problem held to the symmetries its first converged solution has,
// into first->symmetries_found (to 1e-11: Newton from an asymmetric start
// lands on a symmetric solution up to round-off), for the solves at higher
// orders: half the unknowns per symmetry, the same solutions, since the
// equations are equivariant (METHOD.md s.8).
HarmonicBalanceProblem HeldToSymmetriesOf(const HarmonicBalanceProblem& problem, HarmonicBalanceSummary* first) {
  HarmonicBalanceProblem working = problem;
  if (!first->converged() || !first->solution) return working;
  first->symmetries_found = SymmetriesOf(*first->solution, ImposableSymmetries(problem), problem.symmetries, 1e-11);
  working.symmetries.insert(working.symmetries.end(), first->symmetries_found.begin(),
                            first->symmetries_found.end());
  return working;
}

// Several bases without a fixed shape: from the diamond of options.order
// with the guess's harmonics (identified lines, when the guess came from a
// trajectory), enrich until the estimate meets the tolerance. orders_tried
// lists the reach max |k|_1 of each set.
HarmonicBalanceSummary SelectIndexSet(const HarmonicBalanceProblem& problem, const HarmonicSolution& guess,
                                      const HarmonicBalanceOptions& options) {
  const int d = static_cast<int>(problem.frequencies.size());
  HarmonicBalanceOptions o = options;
  o.tolerance = 0;
  std::vector<std::vector<int>> start = HarmonicBasis::Diamond(d, options.order).harmonics();
  if (guess.basis().num_bases() == d)
    for (const auto& k : guess.basis().harmonics()) start.push_back(k);
  HarmonicBasis basis = HarmonicBasis::FromHarmonics(d, start, options.order, "adaptive");
  basis = HarmonicBasis::FromHarmonics(d, start, Reach(basis), "adaptive");
  HarmonicBalanceSummary current = SolveAtOrder(problem, guess, o, &basis);
  std::vector<int> tried = {basis.order()};
  const HarmonicBalanceProblem working = HeldToSymmetriesOf(problem, &current);
  const std::vector<HalfTurnSymmetry> symmetries_found = current.symmetries_found;
  std::optional<HarmonicSolution> lower;
  double threshold = 1e-2 * options.tolerance;
  auto stop = [&](HarmonicBalanceSummary s, const std::string& why) {
    s.orders_tried = tried;
    s.short_of_target = s.solver.converged();
    if (s.short_of_target && !options.soft_tolerance) s.solver.status = SolverStatus::kNoConvergence;
    s.solver.message = "index set selection: " + why + (s.solver.message.empty() ? "" : "; ") + s.solver.message;
    return s;
  };
  const int variables = problem.system.num_variables();
  for (;;) {
    if (!current.converged() || !current.solution)
      return stop(current, "the solve on " + std::to_string(basis.size()) + " harmonics failed");
    const TruncationEstimate e = EstimateTruncation(*current.solution, lower ? &*lower : nullptr, DecayFor(problem.system));
    Record(problem, options, e, &current);
    std::vector<std::vector<int>> added = Enrich(*current.solution, threshold);
    if (current.truncation_estimate <= options.tolerance && (e.calibrated || added.empty())) break;
    if (added.empty()) {
      if (threshold < 1e-15) return stop(current, "no harmonic left to add above round-off");
      threshold *= 0.1;
      continue;
    }
    std::vector<std::vector<int>> grown = basis.harmonics();
    grown.insert(grown.end(), added.begin(), added.end());
    HarmonicBasis next = HarmonicBasis::FromHarmonics(d, grown, 0, "adaptive");
    next = HarmonicBasis::FromHarmonics(d, grown, Reach(next), "adaptive");
    if (next.order() > options.max_order) {
      std::ostringstream why;
      why << "tolerance " << options.tolerance << " not reached by " << basis.size() << " harmonics (reach "
          << basis.order() << "; the next set reaches " << next.order() << " > max_order " << options.max_order
          << ") (estimated error " << current.truncation_estimate << ")";
      return stop(current, why.str());
    }
    const double unknowns = double(variables) * next.num_coefficients();
    if (8 * unknowns * unknowns > options.max_jacobian_bytes) {
      std::ostringstream why;
      why << "tolerance " << options.tolerance << " not reached by " << basis.size()
          << " harmonics; the next set (" << next.size() << ") needs a dense Jacobian over "
          << Gib(options.max_jacobian_bytes) << " (estimated error " << current.truncation_estimate << ")";
      return stop(current, why.str());
    }
    HarmonicBalanceSummary higher = SolveAtOrder(working, *current.solution, o, &next);
    higher.symmetries_found = symmetries_found;
    tried.push_back(next.order());
    if (!higher.converged() || !higher.solution)
      return stop(current, "the solve on " + std::to_string(next.size()) + " harmonics failed (" +
                               higher.solver.message + "); the solution on " + std::to_string(basis.size()) +
                               " is returned");
    lower = current.solution;
    current = std::move(higher);
    basis = next;
  }
  current.orders_tried = tried;
  return current;
}

// The grid of a non-smooth model's order selection above order 64: 16 N
// instead of 128 N samples (at least the 128 x 64 of order 64; METHOD.md
// s.15), MeasureSampling doubling it where the target needs more. 128 N
// keeps continuation's tangent smooth at low orders; at the orders a target
// asks for, the quadrature error of a kink (~M^-2) is 1e-4 of the truncation
// (NLvib's example 03 at N = 400, 164 N samples: 4 digits equal to 2x that),
// and the samples are most of a solve's time.
int LadderSamples(const HarmonicBalanceProblem& problem, int order) {
  return std::max(NonSmoothSamples(order, 16, problem.system.AliasFreeSamples(order, 0)),
                  NonSmoothSamples(std::min(order, 64)));
}

// A non-smooth model's quadrature error (its kinks and jumps fall between
// the samples, METHOD.md s.15) is measured, not assumed: the solution
// selected on M samples is solved again, warm, on 2M; their difference
// bounds the error of the coarser grid, the finer solution is kept, and the
// difference is added to its estimates (a kink's error falls like M^-2, a
// jump's like 1/M: the finer one's is at most the difference). Doubled up to
// three times while truncation and sampling together exceed the tolerance;
// `why` says why the target was not met, empty when it was.
HarmonicBalanceSummary MeasureSampling(const HarmonicBalanceProblem& problem, HarmonicBalanceSummary current,
                                       const HarmonicBalanceOptions& o, const HarmonicBalanceOptions& options,
                                       std::string* why) {
  const double state = current.state_estimate, frequency = current.frequency_estimate;
  HarmonicBalanceOptions finer = o;
  finer.order_continuation = false;
  finer.samples = current.samples;
  for (int doubling = 1; doubling <= 3; ++doubling) {
    for (int& m : finer.samples) m *= 2;
    HarmonicBalanceSummary next = SolveAtOrder(problem, *current.solution, finer);
    if (!next.converged() || !next.solution) {
      *why = "the check of the sampling on " + std::to_string(finer.samples[0]) + " samples failed";
      return current;
    }
    const HarmonicSolution& a = *next.solution;
    const HarmonicSolution& b = *current.solution;
    const double shift = FrequencyDifference(a, b);
    next.sampling_estimate = StateDifference(a, b, DecayModel::kAlgebraic);
    next.orders_tried = current.orders_tried;
    next.symmetries_found = current.symmetries_found;
    next.tolerance = current.tolerance;
    next.tolerance_quantity = current.tolerance_quantity;
    next.estimate_calibrated = current.estimate_calibrated;
    next.state_estimate = state + next.sampling_estimate;
    next.frequency_estimate = frequency >= 0 ? frequency + shift : -1;
    next.truncation_estimate =
        options.tolerance_quantity == TargetQuantity::kFrequency && frequency >= 0 ? next.frequency_estimate
                                                                                    : next.state_estimate;
    current = std::move(next);
    if (current.truncation_estimate <= options.tolerance) return current;
  }
  std::ostringstream message;
  message << "tolerance " << options.tolerance << " not reached with " << finer.samples[0]
          << " samples (estimated error " << current.truncation_estimate << ", of it sampling "
          << current.sampling_estimate << ")";
  *why = message.str();
  return current;
}

// Order selection's first solve (METHOD.md s.8): at half the start order,
// Newton only (a failure there costs little and falls back to the start
// order), so that a problem which needs less than the start order stops
// below it instead of paying for harmonics it does not need (the pendulum at
// 1.5: 17 reach 1e-10, the start is 25). Not converged when there is no
// half order to try (below 8, or not above the guess's own).
HarmonicBalanceSummary SolveAtHalfOrder(const HarmonicBalanceProblem& problem, const HarmonicSolution& initial_guess,
                                        const HarmonicBalanceOptions& options,
                                        std::optional<HarmonicSolution>* converged_below) {
  HarmonicBalanceOptions half = options;
  half.order = options.order / 2;
  HarmonicBalanceSummary s;
  s.solver.status = SolverStatus::kNoConvergence;
  if (!options.order_continuation || half.order < 8 || half.order <= GuessResolution(initial_guess) ||
      !options.samples.empty() || options.rule != SamplingRule::kRhb)
    return s;
  if (half.solver.method == SolverMethod::kAuto) half.solver.method = SolverMethod::kNewton;
  return SolveWithContinuation(problem, initial_guess, half, converged_below);
}

HarmonicBalanceSummary SelectOrder(const HarmonicBalanceProblem& problem,
                                   const HarmonicSolution& initial_guess,
                                   const HarmonicBalanceOptions& options) {
  HarmonicBalanceOptions o = options;
  o.tolerance = 0;
  const DecayModel decay = DecayFor(problem.system);
  std::optional<HarmonicSolution> lower;
  HarmonicBalanceSummary current = SolveAtHalfOrder(problem, initial_guess, o, &lower);
  // The first step from the half order may go straight to the start order.
  const int reach = o.order;
  if (current.converged())
    o.order = current.order;
  else
    current = SolveWithContinuation(problem, initial_guess, o, &lower);
  std::vector<int> tried = {o.order};
  const int bases = static_cast<int>(problem.frequencies.size());
  // Too low a start can have no solution near the physical one (the
  // pendulum near its separatrix at N = 25): start higher rather than fail.
  auto dense_fits = [&](int order) {
    HarmonicBalanceOptions probe = o;
    probe.order = order;
    return DenseJacobianSize(problem, probe).bytes() <= options.max_jacobian_bytes;
  };
  // A non-smooth model's target needs orders in the thousands (METHOD.md
  // s.15): past the dense limit the automatic linear solver is Krylov's
  // anyway (no dense J), so there it is asked for by name.
  const bool krylov_beyond = decay == DecayModel::kAlgebraic && options.solver.linear_solver == LinearSolver::kAuto;
  auto fit = [&](int order) { return krylov_beyond || dense_fits(order); };
  while (options.raise_order_on_failure && !current.converged() && 2 * o.order <= options.max_order &&
         fit(2 * o.order) && tried.size() < 4) {
    o.order *= 2;
    lower.reset();
    current = SolveWithContinuation(problem, initial_guess, o, &lower);
    tried.push_back(o.order);
  }
  auto stop = [&](HarmonicBalanceSummary s, const std::string& why) {
    s.orders_tried = tried;
    s.short_of_target = s.solver.converged();
    if (s.short_of_target && !options.soft_tolerance) s.solver.status = SolverStatus::kNoConvergence;
    s.solver.message = "order selection: " + why + (s.solver.message.empty() ? "" : "; ") +
                       s.solver.message;
    return s;
  };
  const HarmonicBalanceProblem working = HeldToSymmetriesOf(problem, &current);
  const std::vector<HalfTurnSymmetry> symmetries_found = current.symmetries_found;
  // The largest order whose dense Jacobian fits: the sizes grow with the order.
  int fits = o.order;
  for (int lo = o.order, hi = options.max_order; lo <= hi;) {
    const int mid = lo + (hi - lo) / 2;
    if (fit(mid))
      fits = mid, lo = mid + 1;
    else
      hi = mid - 1;
  }
  for (;;) {
    if (!current.converged() || !current.solution)
      return stop(current, "the solve at order " + std::to_string(o.order) + " failed");
    TruncationEstimate e = EstimateTruncation(*current.solution, lower ? &*lower : nullptr, decay);
    // Met by the tail alone: measure the problem's constant once on a lower
    // order (warm, cheaper than this solve) before saying so.
    if (!e.calibrated && Targeted(problem, options, e) <= options.tolerance && o.order > 1) {
      HarmonicBalanceOptions below = o;
      // Half the order for an algebraic decay: its calibration takes the
      // difference for the lower solution's whole error (EstimateTruncation).
      below.order = std::max(1, decay == DecayModel::kAlgebraic ? o.order / 2 : o.order - std::max(2, o.order / 5));
      below.order_continuation = false;
      const HarmonicBalanceSummary check = SolveAtOrder(working, *current.solution, below);
      if (check.converged() && check.solution) {
        lower = check.solution;
        e = EstimateTruncation(*current.solution, &*lower, decay);
      }
    }
    Record(problem, options, e, &current);
    if (current.truncation_estimate <= options.tolerance) break;
    std::ostringstream why;
    if (o.order >= fits && fits < options.max_order) {
      HarmonicBalanceOptions above = o;
      above.order = fits + 1;
      why << "tolerance " << options.tolerance << " not reached by order " << fits
          << ", the largest whose dense Jacobian fits in " << Gib(options.max_jacobian_bytes)
          << " (order " << fits + 1 << " would need " << Gib(DenseJacobianSize(problem, above).bytes())
          << "; max_jacobian_bytes, --max-jacobian-gib) (estimated error " << current.truncation_estimate << ")";
      return stop(current, why.str());
    }
    if (o.order >= options.max_order) {
      why << "tolerance " << options.tolerance << " not reached by max_order " << options.max_order
          << " (estimated error " << current.truncation_estimate << ")";
      return stop(current, why.str());
    }
    HarmonicBalanceOptions n = o;
    n.order = std::min({options.max_order, fits, NextOrder(o.order, bases, e, options.tolerance, o.order < reach ? reach : 0)});
    n.order_continuation = false;  // warm-started from the previous order
    if (!dense_fits(n.order)) n.solver.linear_solver = LinearSolver::kKrylov;
    std::optional<HarmonicBalanceSummary> on_coarse;
    if (decay == DecayModel::kAlgebraic && bases == 1 && n.order > 64 && options.samples.empty() &&
        options.rule != SamplingRule::kHdhb) {
      // The coarser grid, Newton only: a residual sampled more coarsely is
      // rougher at the switches (friction's stick-slip transitions stall
      // Newton at 85 N samples); failing there, the rule's grid.
      HarmonicBalanceOptions coarse = n;
      coarse.samples = {LadderSamples(problem, n.order)};
      if (coarse.solver.method == SolverMethod::kAuto) coarse.solver.method = SolverMethod::kNewton;
      on_coarse = SolveAtOrder(working, *current.solution, coarse);
      if (on_coarse->converged()) n.samples = coarse.samples;
    }
    HarmonicBalanceSummary higher = on_coarse && on_coarse->converged()
                                        ? std::move(*on_coarse)
                                        : SolveAtOrder(working, *current.solution, n);
    higher.symmetries_found = symmetries_found;
    tried.push_back(n.order);
    if (!higher.converged() || !higher.solution)
      // The last converged solution stands, with its estimate.
      return stop(current, "the solve at order " + std::to_string(n.order) + " failed (" + higher.solver.message +
                               "); the solution at order " + std::to_string(o.order) + " is returned");
    lower = current.solution;
    current = std::move(higher);
    o = n;
  }
  current.orders_tried = tried;
  if (decay == DecayModel::kAlgebraic) {
    std::string why;
    current = MeasureSampling(working, std::move(current), o, options, &why);
    if (!why.empty()) return stop(current, why);
  }
  return current;
}

}  // namespace

double SolutionDifference(const HarmonicSolution& a, const HarmonicSolution& b) {
  const HarmonicSolution& big = a.basis().size() >= b.basis().size() ? a : b;
  const HarmonicSolution& small = &big == &a ? b : a;
  const Eigen::MatrixXd c = big.coefficients();
  const Eigen::MatrixXd d = small.OnBasis(big.basis()).coefficients() - c;
  double worst = 0;
  for (int j = 0; j < c.rows(); ++j)
    worst = std::max(worst, d.row(j).cwiseAbs().maxCoeff() / std::max(1.0, c.row(j).cwiseAbs().maxCoeff()));
  for (size_t i = 0; i < a.frequencies().size(); ++i)
    worst = std::max(worst, std::abs(a.frequencies()[i] - b.frequencies()[i]) / std::abs(big.frequencies()[i]));
  return worst;
}

HarmonicBalanceSummary SolveHarmonicBalance(const HarmonicBalanceProblem& problem,
                                            const HarmonicSolution& initial_guess,
                                            const HarmonicBalanceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (std::string why = options.IsValid(); !why.empty())
    throw std::invalid_argument("invalid options: " + why);
  problem.Validate();
  CheckJacobianSize(problem, options);
  if (initial_guess.num_variables() != problem.system.num_variables())
    throw std::invalid_argument("initial guess has " + std::to_string(initial_guess.num_variables()) +
                                " variables, the system " +
                                std::to_string(problem.system.num_variables()));
  const bool adaptive = options.shape == BasisShape::kAdaptive && !options.basis_for_order &&
                        problem.frequencies.size() > 1;
  HarmonicBalanceSummary summary = options.tolerance <= 0 ? SolveWithContinuation(problem, initial_guess, options)
                                   : adaptive             ? SelectIndexSet(problem, initial_guess, options)
                                                          : SelectOrder(problem, initial_guess, options);
  CheckPhysical(problem, options, &summary);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace rmhb

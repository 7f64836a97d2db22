#include "rmhb/monte_carlo.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <time.h>

namespace rmhb {
namespace {

// SplitMix64 (Steele, Lea, Flood 2014): a portable generator, so a seed gives
// the same starts with every compiler and standard library.
std::uint64_t Mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ULL;

// max |a - b| relative to the larger of 1 and max |b|.
double RelativeDistance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

// CPU time of the calling thread: what a solve costs, whatever else the
// machine is doing.
double ThreadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Physical when an alias-free solve at the reference order, started from the
// cluster's solution, converges close to it; then stable or not by Hill.
void Classify(const HarmonicBalanceProblem& problem, const MonteCarloOptions& options,
              int reference_order, SolutionCluster* cluster) {
  cluster->amplitude = cluster->representative.Amplitude(0);
  HarmonicBalanceOptions reference = options.solve;
  reference.order = reference_order;
  reference.rule = SamplingRule::kRhb;
  reference.samples.clear();
  // A physical solution is inside Newton's region of its reference: a few
  // iterations, straight at the reference order. What needs many is a
  // non-physical one wandering off, and there are dozens of those.
  reference.order_continuation = false;
  reference.solver.max_iterations = std::min(reference.solver.max_iterations, 25);
  reference.solver.fallback_max_iterations = std::min(reference.solver.fallback_max_iterations, 5);
  const HarmonicBalanceSummary s = SolveHarmonicBalance(problem, cluster->representative, reference);
  cluster->reference_distance = HUGE_VAL;
  // The reference must itself be physical (HarmonicBalanceSummary::physical:
  // auxiliaries equal to their definitions, frequency not collapsed).
  if (!s.usable()) return;
  const HarmonicBasis& basis = cluster->representative.basis();
  cluster->reference_distance = RelativeDistance(cluster->representative.coefficients(),
                                                 s.solution->OnBasis(basis).coefficients());
  // An unknown frequency is part of the solution too.
  const double w = cluster->representative.frequencies()[0], w_ref = s.solution->frequencies()[0];
  cluster->reference_distance =
      std::max(cluster->reference_distance, std::abs(w - w_ref) / std::max(1.0, std::abs(w_ref)));
  if (cluster->reference_distance >= options.match_tolerance) return;
  cluster->reference = *s.solution;
  cluster->hill = HillStability(problem, *s.solution);
  cluster->solution_class =
      cluster->hill->stable ? SolutionClass::kPhysicalStable : SolutionClass::kPhysicalUnstable;
  if (options.original_check) cluster->original = options.original_check(*s.solution);
}

}  // namespace

const char* ToString(SolutionClass c) {
  switch (c) {
    case SolutionClass::kPhysicalStable: return "physical-stable";
    case SolutionClass::kPhysicalUnstable: return "physical-unstable";
    case SolutionClass::kNonPhysical: return "non-physical";
  }
  return "?";
}

std::string MonteCarloOptions::IsValid() const {
  if (starts < 1) return "starts must be >= 1 (got " + std::to_string(starts) + ")";
  // Every converged start is kept until clustering: ~300 bytes per start and method.
  if (starts > 10'000'000) return "starts must be <= 1e7 (got " + std::to_string(starts) + ")";
  if (!std::isfinite(low) || !std::isfinite(high) || !(low < high))
    return "the range must be finite with low < high";
  if (threads < 0 || threads > 1024) return "threads must be in 0..1024 (0: all cores)";
  if (rules.empty()) return "no sampling rule to compare";
  if (reference_order < 0) return "reference_order must be >= 0";
  if (reference_order > 0 && reference_order <= solve.order)
    return "reference_order must exceed the order";
  if (!(cluster_tolerance > 0) || !(match_tolerance > 0)) return "tolerances must be > 0";
  if (newton_stall_iterations < 0) return "newton_stall_iterations must be >= 0 (0: never)";
  return solve.IsValid();
}

Eigen::MatrixXd RandomStart(std::uint64_t seed, long index, int variables, int coefficients,
                            double low, double high) {
  std::uint64_t state = Mix(seed * kGolden + Mix(static_cast<std::uint64_t>(index) + kGolden));
  Eigen::MatrixXd c(variables, coefficients);
  for (int j = 0; j < variables; ++j)
    for (int k = 0; k < coefficients; ++k) {
      state += kGolden;
      const double u = double(Mix(state) >> 11) * 0x1.0p-53;  // [0, 1)
      c(j, k) = low + (high - low) * u;
    }
  return c;
}

int RuleCensus::non_physical_clusters() const {
  int n = 0;
  for (const auto& c : clusters) n += c.solution_class == SolutionClass::kNonPhysical;
  return n;
}

double RuleCensus::share(SolutionClass c) const {
  double s = 0;
  for (const auto& cluster : clusters)
    if (cluster.solution_class == c) s += cluster.share;
  return s;
}

std::string MonteCarloSummary::BriefReport() const {
  std::ostringstream out;
  out << starts << " starts, order " << order << ", " << threads << " threads, " << seconds << " s:";
  for (const auto& r : rules)
    out << " " << ToString(r.rule) << " " << r.clusters.size() << " solutions ("
        << r.non_physical_clusters() << " non-physical, "
        << r.share(SolutionClass::kNonPhysical) << " %)";
  return out.str();
}

std::string MonteCarloSummary::FullReport() const {
  std::ostringstream out;
  char line[256];
  for (const auto& r : rules) {
    std::snprintf(line, sizeof line,
                  "%s, order %d, M = %d (%s): %ld converged, %ld failed; %zu distinct solutions, "
                  "%d non-physical\n",
                  ToString(r.rule), order, r.samples,
                  r.samples >= r.alias_free_samples ? "alias-free" : "aliased", r.converged,
                  r.failed, r.clusters.size(), r.non_physical_clusters());
    out << line;
    std::snprintf(line, sizeof line, "  physical-stable %.2f %%, physical-unstable %.2f %%, non-physical %.2f %%\n",
                  r.share(SolutionClass::kPhysicalStable), r.share(SolutionClass::kPhysicalUnstable),
                  r.share(SolutionClass::kNonPhysical));
    out << line;
    out << "  share %   class               max|x|       distance   Hill max Re(l)  original max|mu|\n";
    int shown_non_physical = 0;
    for (const auto& c : r.clusters) {
      const bool physical = c.solution_class != SolutionClass::kNonPhysical;
      if (!physical && ++shown_non_physical > 5) continue;
      std::string hill = c.hill ? std::to_string(c.hill->max_real_part) : "-";
      std::string original = "-";
      if (c.original && c.original->ok) {
        double m = 0;
        for (const auto& mu : c.original->multipliers) m = std::max(m, std::abs(mu));
        original = std::to_string(m) + (c.original->stable ? " stable" : " unstable");
        if (c.hill && c.original->stable != c.hill->stable) original += " (DISAGREES)";
      }
      std::snprintf(line, sizeof line, "  %7.2f   %-18s  %-11.6g  %-9.2e  %-14s  %s\n", c.share,
                    ToString(c.solution_class), c.amplitude, c.reference_distance, hill.c_str(),
                    original.c_str());
      out << line;
    }
    if (shown_non_physical > 5)
      out << "  ... and " << shown_non_physical - 5 << " more non-physical solutions\n";
  }
  return out.str();
}

namespace {

void CheckCensusProblem(const HarmonicBalanceProblem& problem, const MonteCarloOptions& options) {
  if (std::string why = options.IsValid(); !why.empty())
    throw std::invalid_argument("Monte Carlo: " + why);
  problem.Validate();
  if (problem.frequencies.size() != 1)
    throw std::invalid_argument("Monte Carlo: periodic problems only (one base frequency)");
  // An autonomous orbit comes back from random starts as many "solutions":
  // shifted by half a period where the phase condition allows it, or solved at
  // w/2, w/3 with every other harmonic zero. Telling those apart from aliasing
  // needs orbit identification this census does not do: refuse rather than
  // call a limit cycle non-physical.
  if (problem.num_unknown_frequencies() > 0)
    throw std::invalid_argument(
        "Monte Carlo: forced (known-frequency) periodic problems only; an autonomous orbit "
        "reappears phase-shifted and at w/2, w/3, ... from random starts");
  // Refuse before the solves, not after them, what Hill's method cannot classify.
  for (const auto& eq : problem.system.equations())
    if (!eq.balance_constant)
      throw std::invalid_argument(
          "Monte Carlo: the stability of a system with pinned recast auxiliaries (constant "
          "term not balanced) is not decided by Hill's method; not supported");
  HarmonicBalanceOptions reference = options.solve;
  reference.order = options.reference_order > 0 ? options.reference_order : std::max(40, 8 * options.solve.order);
  CheckJacobianSize(problem, options.solve);
  CheckJacobianSize(problem, reference);
}

int ThreadCount(const MonteCarloOptions& options, long starts) {
  const int wanted = options.threads > 0 ? options.threads
                                         : static_cast<int>(std::thread::hardware_concurrency());
  return static_cast<int>(std::clamp<long>(wanted, 1, std::max(1L, starts)));
}

// Runs `work` on `threads` threads; the first exception is rethrown here
// once all have ended.
void RunThreads(int threads, const std::function<void()>& work) {
  std::mutex mutex;
  std::exception_ptr failure;
  auto body = [&] {
    try {
      work();
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      if (!failure) failure = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(body);
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace

StartSolves SolveStarts(const HarmonicBalanceProblem& problem, const MonteCarloOptions& options, long first,
                        long stride) {
  CheckCensusProblem(problem, options);
  if (first < 0 || stride < 1) throw std::invalid_argument("SolveStarts: first >= 0 and stride >= 1");
  const HarmonicBasis basis = HarmonicBasis::Periodic(options.solve.order);
  const int n = problem.system.num_variables(), C = basis.num_coefficients();
  const int num_rules = static_cast<int>(options.rules.size());
  StartSolves solves;
  solves.outcomes.assign(num_rules, std::vector<StartOutcome>(options.starts));
  solves.rule_seconds.assign(num_rules, 0);
  const long mine = first < options.starts ? (options.starts - first + stride - 1) / stride : 0;
  solves.threads = ThreadCount(options, mine);
  std::atomic<long> next{0};
  std::mutex mutex;
  long done = 0;
  RunThreads(solves.threads, [&] {
    std::vector<std::unique_ptr<CollocationResidual>> residuals;
    for (SamplingRule rule : options.rules) {
      std::vector<int> alias_free;
      const int samples = SamplesForRule(problem.system, basis, rule, &alias_free)[0];
      residuals.push_back(std::make_unique<CollocationResidual>(problem, basis, Sampling::Uniform(samples), options.solve.condense_definitions));
    }
    std::vector<double> seconds(num_rules, 0);
    SolverOptions solver = options.solve.solver;
    if (solver.newton_stall_iterations == 0) solver.newton_stall_iterations = options.newton_stall_iterations;
    solver.report_condition = false;  // the census reads only the solutions
    for (long j; (j = next.fetch_add(1)) < mine;) {
      const long i = first + j * stride;
      const Eigen::MatrixXd guess = RandomStart(options.seed, i, n, C, options.low, options.high);
      for (int r = 0; r < num_rules; ++r) {
        const double t0 = ThreadCpuSeconds();
        Eigen::VectorXd x = residuals[r]->Pack(guess, problem.frequencies);
        const SolverSummary s = SolveNonlinear(*residuals[r], &x, solver);
        if (s.converged() && x.allFinite()) {
          StartOutcome found;
          residuals[r]->Unpack(x, &found.coefficients, &found.frequencies);
          // An unknown frequency may converge to w <= 0: not a periodic
          // solution in the problem's sense (and w = 0 not one at all).
          bool positive = true;
          for (double w : found.frequencies) positive = positive && w > 0;
          if (positive) solves.outcomes[r][i] = std::move(found);
        }
        seconds[r] += ThreadCpuSeconds() - t0;
      }
      if (options.progress) {
        std::lock_guard<std::mutex> lock(mutex);
        options.progress(++done, mine);
      }
    }
    std::lock_guard<std::mutex> lock(mutex);
    for (int r = 0; r < num_rules; ++r) solves.rule_seconds[r] += seconds[r];
  });
  return solves;
}

MonteCarloSummary CensusOfStarts(const HarmonicBalanceProblem& problem, const MonteCarloOptions& options,
                                 const StartSolves& solves) {
  const auto start = std::chrono::steady_clock::now();
  CheckCensusProblem(problem, options);
  const int num_rules = static_cast<int>(options.rules.size());
  if (static_cast<int>(solves.outcomes.size()) != num_rules || static_cast<int>(solves.rule_seconds.size()) != num_rules)
    throw std::invalid_argument("CensusOfStarts: one list of outcomes per rule expected");
  MonteCarloSummary summary;
  summary.starts = options.starts;
  summary.order = options.solve.order;
  summary.reference_order =
      options.reference_order > 0 ? options.reference_order : std::max(40, 8 * options.solve.order);
  summary.threads = solves.threads;
  const HarmonicBasis basis = HarmonicBasis::Periodic(options.solve.order);
  // Coefficients and (unknown) frequencies alike.
  auto distance = [](const StartOutcome& a, const StartOutcome& b) {
    double d = RelativeDistance(a.coefficients, b.coefficients);
    for (size_t i = 0; i < a.frequencies.size(); ++i)
      d = std::max(d, std::abs(a.frequencies[i] - b.frequencies[i]) /
                          std::max(1.0, std::abs(b.frequencies[i])));
    return d;
  };
  for (int r = 0; r < num_rules; ++r) {
    RuleCensus census;
    census.rule = options.rules[r];
    std::vector<int> alias_free;
    census.samples = SamplesForRule(problem.system, basis, census.rule, &alias_free)[0];
    census.alias_free_samples = alias_free[0];
    census.solve_seconds = solves.rule_seconds[r];
    const std::vector<StartOutcome>& outcomes = solves.outcomes[r];
    if (static_cast<long>(outcomes.size()) != options.starts)
      throw std::invalid_argument("CensusOfStarts: one outcome per start expected");
    // In start order, so the clusters and their representatives depend on the
    // seed only.
    std::vector<long> first;  // representative start of each cluster
    std::vector<long> count;
    for (long i = 0; i < options.starts; ++i) {
      const StartOutcome& x = outcomes[i];
      if (x.coefficients.size() == 0) {
        ++census.failed;
        continue;
      }
      ++census.converged;
      size_t c = 0;
      while (c < first.size() && distance(x, outcomes[first[c]]) >= options.cluster_tolerance) ++c;
      if (c == first.size()) first.push_back(i), count.push_back(0);
      ++count[c];
    }
    for (size_t c = 0; c < first.size(); ++c) {
      const StartOutcome& f = outcomes[first[c]];
      census.clusters.emplace_back(
          HarmonicSolution(basis, f.frequencies, f.coefficients, problem.system.variables()));
      census.clusters.back().count = count[c];
      census.clusters.back().share = 100.0 * count[c] / census.converged;
    }
    // Classification is a solve at the reference order per cluster (HDHB
    // finds dozens): in parallel too.
    std::atomic<size_t> next_cluster{0};
    RunThreads(ThreadCount(options, static_cast<long>(census.clusters.size())), [&] {
      for (size_t c; (c = next_cluster.fetch_add(1)) < census.clusters.size();)
        Classify(problem, options, summary.reference_order, &census.clusters[c]);
    });
    std::stable_sort(census.clusters.begin(), census.clusters.end(),
                     [](const SolutionCluster& a, const SolutionCluster& b) { return a.count > b.count; });
    summary.rules.push_back(std::move(census));
  }
  summary.seconds = Seconds(start);
  return summary;
}

MonteCarloSummary RunMonteCarlo(const HarmonicBalanceProblem& problem, const MonteCarloOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  MonteCarloSummary summary = CensusOfStarts(problem, options, SolveStarts(problem, options));
  summary.seconds = Seconds(start);
  return summary;
}

}  // namespace rmhb

#include "rmhb/cli/montecarlo_command.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "integrators/floquet.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/cli/solve_setup.h"
#include "rmhb/monte_carlo.h"
#include "rmhb/sweep/mpi.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;

json Complex(const std::vector<std::complex<double>>& values) {
  json out = json::array();
  for (const auto& v : values) out.push_back({Number(v.real()), Number(v.imag())});
  return out;
}

json ClusterJson(const SolutionCluster& c) {
  json out = {{"class", ToString(c.solution_class)},
              {"count", c.count},
              {"share", Number(c.share)},
              {"amplitude", Number(c.amplitude)},
              {"reference_distance", Number(c.reference_distance)}};
  json stability = json::object();
  if (c.hill)
    stability["hill"] = {{"stable", c.hill->stable},
                         {"max_real_part", Number(c.hill->max_real_part)},
                         {"exponents", Complex(c.hill->exponents)},
                         {"multipliers", Complex(c.hill->multipliers)},
                         {"trivial", c.hill->trivial}};
  if (c.original) {
    stability["floquet"] = {{"ok", c.original->ok},
                            {"stable", c.original->stable},
                            {"multipliers", Complex(c.original->multipliers)},
                            {"closure_error", Number(c.original->closure_error)},
                            {"message", c.original->message}};
    if (c.hill && c.original->ok) stability["agree"] = c.hill->stable == c.original->stable;
  }
  out["stability"] = stability;
  out["solution"] = SolutionJson(c.representative);
  return out;
}

// A progress bar on stderr, only for a person watching a terminal.
void ShowProgress(long done, long total) {
  const int width = 40;
  const long step = std::max(1L, total / 200);
  if (done % step != 0 && done != total) return;
  const int filled = static_cast<int>(width * done / total);
  std::fprintf(stderr, "\r[%.*s%*s] %3d%% %ld/%ld starts", filled,
               "########################################", width - filled, "",
               static_cast<int>(100 * done / total), done, total);
  if (done == total) std::fprintf(stderr, "\r%*s\r", width + 40, "");
}

// A start's outcome as numbers for MPI: converged flag, coefficients
// (row-major), frequencies; the same length for every start.
void PackOutcome(const StartOutcome& o, int coefficients, int bases, std::vector<double>* out) {
  const bool converged = o.coefficients.size() > 0;
  out->push_back(converged);
  for (int i = 0; i < coefficients; ++i)
    out->push_back(converged ? o.coefficients(i / o.coefficients.cols(), i % o.coefficients.cols()) : 0.0);
  for (int b = 0; b < bases; ++b) out->push_back(converged ? o.frequencies[b] : 0.0);
}

// The census over `ranks` processes: rank r solves starts r, r + ranks, ...;
// rank 0 gathers every outcome and classifies. The same census as one
// process (it depends on the outcomes by start index only); other ranks get
// an empty summary.
MonteCarloSummary Census(const HarmonicBalanceProblem& problem, const MonteCarloOptions& options, int rank,
                         int ranks) {
  if (ranks == 1) return rmhb::RunMonteCarlo(problem, options);
  const auto begin = std::chrono::steady_clock::now();
  StartSolves solves = SolveStarts(problem, options, rank, ranks);
  const int rows = problem.system.num_variables(), cols = HarmonicBasis::Periodic(options.solve.order).num_coefficients();
  const int bases = static_cast<int>(problem.frequencies.size()), record = 1 + rows * cols + bases;
  std::vector<double> mine;
  for (const auto& rule : solves.outcomes)
    for (long i = rank; i < options.starts; i += ranks) PackOutcome(rule[i], rows * cols, bases, &mine);
  const std::vector<double> all = sweep::GatherToRoot(mine);
  for (double& s : solves.rule_seconds) s = sweep::SumToRoot(s);
  if (rank != 0) return {};
  const double* p = all.data();
  for (int r = 0; r < ranks; ++r)
    for (auto& rule : solves.outcomes)
      for (long i = r; i < options.starts; i += ranks, p += record) {
        if (p[0] == 0) continue;
        rule[i].coefficients = Eigen::Map<const Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(p + 1, rows, cols);
        rule[i].frequencies.assign(p + 1 + rows * cols, p + record);
      }
  MonteCarloSummary summary = CensusOfStarts(problem, options, solves);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return summary;
}

}  // namespace

void AddMonteCarloOptions(CLI::App* app, MonteCarloArgs* a) {
  app->add_option("model", a->model, "Example name (see `rmhb list`) or model file; periodic only")
      ->required();
  app->add_option("--set", a->set, "Override a parameter: --set name=value (repeatable)");
  app->add_option("--order,-N", a->order, "Harmonic order N of every solve (default 3)");
  app->add_option("--starts", a->starts, "Number of random starts (default 10000)");
  app->add_option("--range", a->range,
                  "Every coefficient of a start is uniform in lo:hi (default -2:2)");
  app->add_option("--seed", a->seed, "Random seed; the result depends on it only, not on --threads (default 1)");
  app->add_option("--threads", a->threads, "Worker threads (default 0: all cores)");
  app->add_option("--methods", a->methods, "Sampling rules to compare, from rhb, hdhb, aft (default rhb,hdhb)");
  app->add_option("--reference-order", a->reference_order,
                  "Order of the alias-free solve that decides physical (default max(40, 8 N))");
  app->add_option("--match-tolerance", a->match_tolerance,
                  "Largest relative distance to its reference solve for a solution to count as "
                  "physical (default 0.05)");
  app->add_option("--solver", a->solver, "newton, lm, tikhonov or auto (default: Newton, then L-M)")
      ->check(CLI::IsMember({"auto", "newton", "lm", "tikhonov"}));
  app->add_option("--max-iterations", a->max_iterations, "Iteration limit per start (default 100)")
      ->check(CLI::Range(1, 100000));
  app->add_flag("--no-floquet", a->no_floquet,
                "Skip the Floquet multipliers of the original equations (CVODE)");
  app->add_flag("--json", a->json, "Machine-readable output");
}

int RunMonteCarlo(const MonteCarloArgs& a, int rank, int ranks) {
  SolveSettings settings;
  settings.model = a.model;
  settings.set = a.set;
  settings.order = a.order;
  settings.solver = a.solver;
  settings.max_iterations = a.max_iterations;
  const PreparedSolve prepared = PrepareSolve(settings);
  const ProblemSource& source = prepared.source;

  const std::vector<double> range = ParseNumberList(a.range, "--range");
  if (range.size() != 2 || !(range[0] < range[1]))
    throw std::invalid_argument("--range expects lo:hi with lo < hi, got '" + a.range + "'");
  MonteCarloOptions options;
  options.starts = a.starts;
  options.low = range[0];
  options.high = range[1];
  options.seed = a.seed;
  options.threads = a.threads;
  options.reference_order = a.reference_order;
  options.match_tolerance = a.match_tolerance;
  options.solve = prepared.options;
  options.rules.clear();
  std::string item;
  for (char c : a.methods + ",") {
    if (c != ',') {
      item += c;
      continue;
    }
    options.rules.push_back(ParseSamplingRule(item));
    item.clear();
  }
  if (isatty(STDERR_FILENO) && rank == 0) options.progress = ShowProgress;
  if (source.original && !a.no_floquet)
    options.original_check = [&source](const HarmonicSolution& s) {
      integrators::FloquetOptions fo;
      fo.autonomous = source.problem.num_unknown_frequencies() > 0;
      if (source.stiff) fo.integrator.method = integrators::IntegratorOptions::Method::kBdf;
      const integrators::FloquetReport f = integrators::FloquetMultipliers(
          source.original(s.frequencies()), source.state(s, 0.0), 0.0, 2 * M_PI / s.frequencies()[0], fo);
      return OriginalCheck{f.ok, f.stable, f.multipliers, f.closure_error, f.message};
    };
  const MonteCarloSummary summary = Census(source.problem, options, rank, ranks);
  if (rank != 0) return kExitOk;

  bool all_failed = false;
  json methods = json::array();
  for (const auto& r : summary.rules) {
    all_failed = all_failed || r.converged == 0;
    json clusters = json::array();
    for (const auto& c : r.clusters) clusters.push_back(ClusterJson(c));
    methods.push_back({{"method", ToString(r.rule)},
                       {"samples", r.samples},
                       {"alias_free_samples", r.alias_free_samples},
                       {"alias_free", r.samples >= r.alias_free_samples},
                       {"converged", r.converged},
                       {"failed", r.failed},
                       {"distinct_solutions", r.clusters.size()},
                       {"non_physical_solutions", r.non_physical_clusters()},
                       {"shares", {{"physical_stable", Number(r.share(SolutionClass::kPhysicalStable))},
                                   {"physical_unstable", Number(r.share(SolutionClass::kPhysicalUnstable))},
                                   {"non_physical", Number(r.share(SolutionClass::kNonPhysical))}}},
                       {"solve_cpu_seconds", r.solve_seconds},
                       {"clusters", clusters}});
  }
  if (a.json) {
    json out = {{"model", a.model},        {"starts", summary.starts},
                {"range", {range[0], range[1]}}, {"seed", a.seed},
                {"order", summary.order},  {"reference_order", summary.reference_order},
                {"match_tolerance", a.match_tolerance},
                {"threads", summary.threads}, {"ranks", ranks}, {"seconds", summary.seconds},
                {"methods", methods}};
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("%s: %s\n%ld starts, every coefficient uniform in [%g, %g], seed %llu; reference: "
                "alias-free RHB at order %d; %d threads x %d rank(s), %.3f s\n\n%s",
                source.name.c_str(), source.equation.c_str(), summary.starts, range[0], range[1],
                static_cast<unsigned long long>(a.seed), summary.reference_order, summary.threads,
                ranks, summary.seconds, summary.FullReport().c_str());
  }
  if (all_failed) {
    std::fprintf(stderr, "rmhb: not converged: a method converged from none of the %ld starts\n",
                 summary.starts);
    return kExitNotConverged;
  }
  return kExitOk;
}

}  // namespace rmhb::cli

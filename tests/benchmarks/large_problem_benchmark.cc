// Large problems (issue 15, METHOD.md s.17): time and peak memory of Newton
// with the dense, sparse and Krylov linear solvers against the unknowns, on
// a problem whose Jacobian is dense (Van der Pol, one variable after
// condensation) and one whose Jacobian is block-sparse (the 40-DOF forced
// cubic chain, tests/benchmarks/models/chain40.yaml); and Van der Pol's
// period against the CVODE event period (examples::VanDerPolPeriodByCvode).
// Every configuration runs in a child process of its own, so that its peak
// resident memory (getrusage) is its own.
//   large_problem_benchmark vdp EPS N SOLVER [COUPLING]   one Van der Pol solve
//   large_problem_benchmark chain N SOLVER                one chain solve
//   large_problem_benchmark table [MAX_UNKNOWNS]          the README's table
// SOLVER: auto, dense, sparse, krylov. Times are wall clock (report the load).

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "examples/example_system.h"
#include "examples/references.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/model.h"

using namespace rmhb;

namespace {

std::string ModelPath(const char* name) { return std::string(RMHB_BENCHMARK_MODELS) + "/" + name; }

struct Run {
  HarmonicBalanceSummary summary;
  double seconds = 0;
};

Run SolveOnce(const HarmonicBalanceProblem& problem, const HarmonicSolution& guess, int order,
              LinearSolver solver, double coupling) {
  HarmonicBalanceOptions o;
  o.order = order;
  o.solver.linear_solver = solver;
  if (coupling > 0) o.solver.krylov_coupling = coupling;
  if (const char* rebuild = std::getenv("RMHB_KRYLOV_REBUILD")) o.solver.krylov_rebuild_iterations = std::atoi(rebuild);
  o.solver.verbose = std::getenv("RMHB_VERBOSE") != nullptr;
  const auto start = std::chrono::steady_clock::now();
  Run run{SolveHarmonicBalance(problem, guess, o), 0};
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

void Print(const char* problem, int order, const Run& run, double period_error) {
  const SolverSummary& s = run.summary.solver;
  std::printf("%-7s %6d %8d %-7s %-10s %4d %6d %9.3f %8.0f %10.2e\n", problem, order, s.num_unknowns,
              ToString(s.linear_solver), run.summary.usable() ? "usable" : ToString(s.status), s.iterations,
              s.linear_iterations, run.seconds, PeakMemoryBytes() / (1 << 20), period_error);
  std::fflush(stdout);
}

int VanDerPol(double eps, int order, LinearSolver solver, double coupling) {
  const examples::ExampleSetup e = examples::BuildExample("vanderpol", {{"eps", eps}});
  const Run run = SolveOnce(e.problem, e.guess, order, solver, coupling);
  double error = NAN;
  if (run.summary.usable()) {
    const double period = 2 * M_PI / run.summary.solution->frequencies()[0];
    error = std::abs(period - examples::VanDerPolPeriodByCvode(eps)) / period;
  }
  Print("vdp", order, run, error);
  return run.summary.usable() ? 0 : 1;
}

int Chain(int order, LinearSolver solver) {
  const Model model = LoadModel(ModelPath("chain40.yaml"));
  const Run run = SolveOnce(model.problem, GuessAtOrder(model, order), order, solver, 0);
  Print("chain40", order, run, NAN);
  return run.summary.usable() ? 0 : 1;
}

// One configuration in a child process (its own peak memory), with a
// time limit: a configuration past it is reported as such.
void Child(const std::vector<std::string>& args, int seconds) {
  std::fflush(stdout);
  const pid_t pid = fork();
  if (pid == 0) {
    alarm(seconds);
    std::vector<char*> argv;
    static std::string self = "/proc/self/exe";
    argv.push_back(self.data());
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv("/proc/self/exe", argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  if (WIFSIGNALED(status))
    std::printf("%-7s %6s %8s %-7s over %d s (or out of memory)\n", args[0].c_str(), args[2].c_str(), "",
                args.back().c_str(), seconds);
}

int Table(int max_unknowns) {
  std::printf("%-7s %6s %8s %-7s %-10s %4s %6s %9s %8s %10s\n", "problem", "N", "unknowns", "linear",
              "status", "it", "gmres", "seconds", "peak MiB", "period err");
  const int limit = 180;
  // Van der Pol (eps = 20, dense coupling): unknowns 2N + 2.
  for (int order : {500, 1000, 2500, 5000, 12500, 25000, 50000}) {
    if (2 * order + 2 > max_unknowns) break;
    for (const char* solver : {"dense", "sparse", "krylov"}) {
      if (std::string(solver) == "dense" && order > 2500) continue;    // > 1 GB, minutes
      if (std::string(solver) == "sparse" && order > 2500) continue;   // a dense block: the same fill
      Child({"vdp", "20", std::to_string(order), solver}, limit);
    }
  }
  // The chain (block tridiagonal): unknowns 40 (2N + 1).
  for (int order : {12, 25, 62, 125, 250, 625, 1250}) {
    if (40 * (2 * order + 1) > max_unknowns) break;
    for (const char* solver : {"dense", "sparse", "krylov"}) {
      if (std::string(solver) == "dense" && order > 62) continue;
      Child({"chain", std::to_string(order), solver}, limit);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "table";
  if (mode == "vdp" && argc >= 5)
    return VanDerPol(std::atof(argv[2]), std::atoi(argv[3]), ParseLinearSolver(argv[4]),
                     argc > 5 ? std::atof(argv[5]) : 0);
  if (mode == "chain" && argc >= 4) return Chain(std::atoi(argv[2]), ParseLinearSolver(argv[3]));
  if (mode == "table") return Table(argc > 2 ? std::atoi(argv[2]) : 100000);
  std::fprintf(stderr,
               "usage: large_problem_benchmark vdp EPS N SOLVER [COUPLING] | chain N SOLVER | table [MAX_UNKNOWNS]\n");
  return 2;
}

#ifndef RMHB_CLI_SOLVE_SETUP_H_
#define RMHB_CLI_SOLVE_SETUP_H_

// What every command that solves shares (solve, analyze, convergence,
// continuation, montecarlo): the model and its parameters, the order, the
// method, solver and sampling options; and the problem, options and guess
// they make. One place, so that `--order 25 --method hdhb` means the same to
// every command.

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rmhb/cli/problem_source.h"
#include "rmhb/harmonic_balance.h"

namespace CLI {
class App;
}

namespace rmhb::cli {

struct SolveSettings {
  std::string model;
  std::vector<std::string> set;  // name=value
  int order = -1;                // -1: the model's default
  int samples = -1;              // -1: by the method's rule
  bool order_given = false, samples_given = false;  // so that an explicit -1 is refused
  double residual_tol = 1e-15;   // max|F| at convergence
  std::string method = "rhb";
  std::string solver = "auto";
  std::string scaling = "equilibrate";  // SolverOptions::scaling
  int max_iterations = 100;
  bool allow_aliasing = false;
  std::string frequencies;  // "w1,w2"; "?w" marks an unknown with guess w
  std::string sampling = "torus";
  std::string shape = "diamond";
  bool shape_given = false;
  double tol = 0;  // > 0: choose the order automatically (HarmonicBalanceOptions::tolerance)
  int max_order = 5000;  // the order selection's limit
  double max_jacobian_gib = 4;  // HarmonicBalanceOptions::max_jacobian_bytes in GiB
};

// The model positional argument and the options above.
void AddSolveSettings(CLI::App* app, SolveSettings* settings);

struct PreparedSolve {
  ProblemSource source;
  HarmonicBalanceOptions options;
  HarmonicSolution guess;  // at options.order, with the problem's frequencies
};

// Loads the model with --set (and `overrides` on top, e.g. a continuation
// parameter's value) and applies --frequencies. Throws
// std::invalid_argument naming the bad value.
ProblemSource LoadSolveProblem(const SolveSettings& settings,
                               const std::map<std::string, double>& overrides = {});

// LoadSolveProblem, then the options and the starting guess.
PreparedSolve PrepareSolve(const SolveSettings& settings,
                           const std::map<std::string, double>& overrides = {});

// "a,b,c" or "a:b:c" -> numbers; throws std::invalid_argument naming `what`
// and the item that is not a finite number.
std::vector<double> ParseNumberList(const std::string& text, const char* what);

// JSON cannot hold NaN/inf; a non-finite number must never be printed as a
// result, so it becomes null.
nlohmann::json Number(double v);

// The solution as the documented JSON fields: frequencies, harmonics,
// coefficients (original variables) and auxiliary_coefficients.
nlohmann::json SolutionJson(const HarmonicSolution& solution);

// The physical check of a converged solve (HarmonicBalanceSummary::physical):
// "physical", "non_physical" (why, when not), and with a definition check
// "definition_error", "definition_worst", "definition_worst_time",
// "definition_tolerance". Empty when the solve did not converge.
nlohmann::json PhysicalJson(const HarmonicBalanceSummary& summary);
// The verdict in words: "yes: max |solved - definition| ..." or "NO: why".
std::string PhysicalLine(const HarmonicBalanceSummary& summary);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_SOLVE_SETUP_H_

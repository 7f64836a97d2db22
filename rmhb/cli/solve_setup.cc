#include "rmhb/cli/solve_setup.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <stdexcept>

#include "examples/example_model.h"

namespace rmhb::cli {
namespace {

// "1e9" as 1000000000 for integer options, so that a size written as a
// power of ten reaches the size checks (exit 2 naming the memory it needs)
// instead of a conversion error. Anything else is left to CLI11.
std::string WholeNumber(std::string text) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    return text;
  }
  if (used != text.size() || v != std::floor(v) || std::abs(v) > 2147483647.0) return text;
  return std::to_string(static_cast<long>(v));
}

}  // namespace

void AddSolveSettings(CLI::App* app, ModelSettings* m) {
  SolveSettings* a = &m->solve;
  app->add_option("model", m->model,
                  "Example name (see `rmhb list`) or model file (examples/models/*.yaml)")
      ->required();
  app->add_option("--set", m->set, "Override a parameter: --set name=value (repeatable)");
  app->add_option("--order,-N,--p", a->order,
                  "Harmonic order: N for one base frequency, p (|m|+|n| <= p) for several "
                  "(default: the model's)")
      ->transform(WholeNumber)
      ->each([a](const std::string&) { a->order_given = true; });
  app->add_option("--frequencies", a->frequencies,
                  "Base frequencies w1[,w2]: values of known ones, guesses of unknown ones; "
                  "prefix ? to make one unknown (e.g. 2.3,?0.95)");
  app->add_option("--sampling", a->sampling,
                  "Quasi-periodic sampling: torus (2-D grid, default) or gcd (Theorem 2)")
      ->check(CLI::IsMember({"torus", "gcd"}));
  app->add_option("--basis", a->shape,
                  "Quasi-periodic index set: diamond (|m|+|n| <= p) or box (default: the "
                  "model's own when it has one, else diamond)")
      ->check(CLI::IsMember({"diamond", "box"}))
      ->each([a](const std::string&) { a->shape_given = true; });
  app->add_option("--samples,-M", a->samples,
                  "Collocation samples M (default: by --method; below the alias-free bound "
                  "needs --allow-aliasing)")
      ->transform(WholeNumber)
      ->each([a](const std::string&) { a->samples_given = true; });
  app->add_option("--method", a->method,
                  "rhb (alias-free M, default), hdhb (M = 2N+1, aliases), aft (M = 2^k >= 2 phi N+1)")
      ->check(CLI::IsMember({"rhb", "hdhb", "aft"}));
  app->add_option("--solver", a->solver,
                  "newton, lm (Levenberg-Marquardt), tikhonov, or auto (Newton when square, "
                  "L-M otherwise)")
      ->check(CLI::IsMember({"auto", "newton", "lm", "tikhonov"}));
  app->add_option("--scaling", a->scaling,
                  "equilibrate (default: Ruiz row and column equilibration, unit-invariant convergence "
                  "tests, so a model in SI units converges like its nondimensional form) or none "
                  "(absolute tests on max|F| and the step)")
      ->check(CLI::IsMember({"equilibrate", "none"}));
  app->add_option("--linear-solver", a->linear_solver,
                  "Newton's linear solver: auto (default: dense LU up to 800 unknowns, above it "
                  "GMRES on exact Jacobian-vector products, the sparse LU if that fails on a "
                  "block-sparse Jacobian), dense, sparse (UMFPACK) or krylov (GMRES, "
                  "UMFPACK-preconditioned)")
      ->check(CLI::IsMember({"auto", "dense", "sparse", "krylov"}));
  app->add_option("--max-iterations", a->max_iterations, "Nonlinear solver iteration limit (default 100)")
      ->check(CLI::Range(1, 100000));
  app->add_flag("--allow-aliasing", a->allow_aliasing, "Accept M below the alias-free bound");
  app->add_option("--residual-tol", a->residual_tol,
                  "Converged when max|F| <= this (default 1e-15; finite and > 0); with "
                  "--scaling equilibrate on the scaled residual, relative to the scaled unknowns");
  app->add_option("--tol", a->tol,
                  "Accuracy target: from --order (or the model's default), raise the order in small "
                  "steps, warm-started, until the estimated truncation error (coefficient tail, "
                  "calibrated on a lower order) is within TOL; reports the orders tried and the "
                  "estimates. solve and analyze aim at 1e-10 by default unless --order is given. "
                  "Not reached by --max-order: exit 3");
  app->add_option("--tol-quantity", a->tol_quantity,
                  "What --tol bounds: state (the time-domain solution, relative per variable; "
                  "default) or frequency (the unknown base frequencies, relative)")
      ->check(CLI::IsMember({"state", "frequency"}));
  app->add_option("--max-jacobian-gib", a->max_jacobian_gib,
                  "Refuse (exit 2) an order whose dense Jacobian needs more than this many GiB; "
                  "--tol stops at the largest order under it (default 4)");
  app->add_option("--max-order", a->max_order, "Highest order --tol may choose (default 5000)")
      ->check(CLI::Range(1, 20000));
  app->add_option("--equations", a->equations,
                  "Equations a model file is solved on: recast (polynomial, RHB alias-free, default), "
                  "original (as written, evaluated pointwise: fewer unknowns, aliasing checked on a "
                  "grid twice as fine) or auto (original when the recast needs auxiliaries)")
      ->check(CLI::IsMember({"recast", "original", "auto"}));
}

PreparedSolve Prepare(const ModelSettings& m, const std::map<std::string, double>& overrides) {
  if (const std::string error = m.solve.IsValid(); !error.empty()) throw std::invalid_argument(error);
  std::map<std::string, double> values = ParseOverrides(m.set);
  for (const auto& [name, value] : overrides) values[name] = value;
  if (const std::string error = m.solve.IsValid(); !error.empty()) throw std::invalid_argument(error);
  return PrepareSolve(examples::LoadModelOrExample(m.model, values, ParseEquationsRoute(m.solve.equations)),
                      m.solve);
}

}  // namespace rmhb::cli

#ifndef RMHB_MODEL_ORIGINAL_SYSTEM_H_
#define RMHB_MODEL_ORIGINAL_SYSTEM_H_

// The user's ORIGINAL equations as an explicit first-order ODE, for the time
// integrators (validation against the harmonic balance solution). The recast
// system is exactly equivalent on the solution manifold but not a good ODE to
// integrate: its auxiliaries are only pinned at t = 0 and drift, and its
// algebraic equations make it a DAE. So the integrators see the model as
// written:
//   states y = (x, x', ..., x^(n_x - 1), y, y', ...),  n_x the order of x,
// and the highest derivatives h = (x^(n_x), ...) are solved for at each
// evaluation. They must appear linearly (they may be coupled, with
// coefficients depending on the state: the asymmetric pendulum's mass matrix
// M(y) h = b(t, y), Rayleigh-Plesset's R R''): M and b are compiled to a tape
// (compiled_function.h) once, and every call evaluates them and solves the
// small dense system by Gaussian elimination with partial pivoting.
//
// Why not solve M h = b symbolically (GiNaC lsolve) once: Cramer-style
// closed forms swell with the size of M and lose accuracy where M is
// ill-conditioned, while the numeric solve of a 2x2 or 3x3 system costs less
// than evaluating the trigonometric terms. Highest derivatives that appear
// nonlinearly (sin(x'')) are refused with a clear message: they would need a
// Newton solve per evaluation and have no unique solution in general.
//
// If M is singular at a state, rhs fills ydot with NaN (the integrator then
// reports the failure). rhs is thread-safe (per-thread work buffers) and
// allocation-free after its first call in a thread.
//
// A model with an algebraic equation (a variable that appears without
// derivatives: `y - x^2 = 0`, `z*(1 + x^2) = 1`) is no explicit ODE; it is
// kept as the implicit DAE F(t, y, y') = 0 for SUNDIALS IDA
// (integrators::IntegrateDae, which makes the initial values consistent with
// IDACalcIC): the states are those above plus each algebraic variable, the
// residual is the chains x' - x_d1 = 0, ... then the equations as written,
// with each highest derivative read from y'. Then `residual` is set and
// `rhs` is empty; IDA needs index 1 (the algebraic equations solvable for
// the algebraic variables), and reports a failure otherwise.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rmhb/harmonic_solution.h"
#include "rmhb/model/compiled_function.h"
#include "rmhb/model/model_definition.h"

namespace rmhb::model {

// Where a state of the original system lives in the recast system: the
// value (derivative = 0) or the derivative (1) of recast variable `variable`.
struct StateSource {
  int variable = -1;
  int derivative = 0;
};

struct OriginalSystem {
  int dimension = 0;
  std::vector<std::string> state_names;  // "x", "x'", "y", "y'", ...
  // Base frequency values bound into the forcing terms (known values; the
  // guesses for unknown ones until BindFrequencies is called with solved ones).
  std::vector<double> frequencies;
  std::function<void(double t, const double* y, double* ydot)> rhs;
  // Set instead of rhs when the model has algebraic variables (see above).
  std::function<void(double t, const double* y, const double* yp, double* residual)> residual;
  std::vector<bool> differential;  // per state; false for algebraic variables
  // Piecewise-smooth equations (max, abs, sign, ...: METHOD.md s.15): the
  // number of switches and rhs with each held on a branch (+1 or -1), the
  // switching functions written into `arguments` when not null, for
  // event-located integration (integrators/switched_integration.h). rhs
  // itself takes every switch by its argument's sign. Explicit ODEs only.
  // Coulomb terms coulomb(v, Fn) are switches too (after the others): mode
  // +1 or -1 slides with the force +-Fn, 0 sticks (v held at zero by the
  // force that does it, solved with the highest derivatives); their argument
  // is v when sliding, Fn - |force| when stuck; `next_mode` decides stick or
  // slip at a crossing (direction +-1) or at the start (0). rhs slides by
  // the sign of v (smeared; the switched integration is the reference).
  int num_switches = 0;
  int num_coulomb = 0;
  std::function<void(double t, const double* y, const signed char* modes, double* ydot, double* arguments)>
      switched_rhs;
  std::function<int(double t, const double* y, int k, int direction, const signed char* modes)> next_mode;
  bool is_dae() const { return static_cast<bool>(residual); }
  // One per state; filled by Recast (empty when built alone).
  std::vector<StateSource> sources;

  // The state at time t from a recast (harmonic balance) solution.
  std::vector<double> StateFromSolution(const HarmonicSolution& solution, double t) const;
  // Rebinds rhs to other base frequency values (e.g. the solved ones).
  void BindFrequencies(const std::vector<double>& frequencies);

  // The compiled evaluator rhs uses: inputs (t, y, frequencies), outputs
  // the mass matrix M (row-major) then b.
  std::shared_ptr<const CompiledFunction> mass_and_rhs;  // outputs: M (row-major), then b
  // DAE: inputs (t, y, the highest derivatives of the differential
  // variables, frequencies), outputs the equations' residuals.
  std::shared_ptr<const CompiledFunction> equations;
  std::vector<int> orders;  // order of each user variable (0: algebraic)
};

// Builds the first-order system of the model's equations with the parameter
// overrides applied and the base frequencies bound to `frequencies` (one per
// base). Throws ModelError when the model is neither an explicit ODE in its
// highest derivatives (they appear nonlinearly) nor a DAE (no variable has a
// derivative).
OriginalSystem BuildOriginalSystem(const ModelDefinition& model, const ParameterValues& overrides,
                                   const std::vector<double>& frequencies);

}  // namespace rmhb::model

#endif  // RMHB_MODEL_ORIGINAL_SYSTEM_H_

#ifndef RMHB_MODEL_RECAST_H_
#define RMHB_MODEL_RECAST_H_

// The automatic recast (METHOD.md s.4): a model in natural notation becomes a
// polynomial implicit DAE g_i(t, z, z') = 0 of first order, the only input
// the solver core accepts, together with the point conditions and a guess.
//
//   ModelDefinition m = LoadModelFile("pendulum.yaml");
//   RecastResult r = Recast(m, {{"theta0", 1.5}});
//   HarmonicBalanceOptions o;  o.order = 25;
//   auto s = SolveHarmonicBalance(r.problem, r.InitialGuess(o.order), o);
//
// Rules, applied bottom-up on the GiNaC expression tree:
//  - derivatives: x'' becomes (x_d1)' with the chain equation x' - x_d1 = 0;
//    x^(n) is a state for n below the order, the top derivative stays a
//    derivative z' (second derivatives inside nonlinear terms stay implicit:
//    x y y'' is the cubic monomial x * y * (y_d1)'). x' counts one degree.
//  - integer powers stay; 1/p: r with r p - 1 = 0 (when p has degree >= 2,
//    first q = p with q - p = 0, keeping the degree at 2: the appendix form);
//  - p^(a/b) with b <= 4: beta with beta^b - p = 0, then beta^a (or
//    (1/beta)^|a|); other real exponents n (0.3, pi): u = p^n through
//    u' - n p' u r = 0 with r = 1/p (pinned), which keeps the degree at
//    deg(p') + 2 instead of b; variable exponents p^q: exp(q log p);
//  - exp, log, sin & cos (a pair), tan, asin, acos, atan, sinh & cosh (a
//    pair), tanh through their derivative (the appendix table of the paper):
//    u = exp(g): u' - g' u = 0, s = sin g, c = cos g: s' - g' c, c' + g' s,
//    tan: u' - g'(1 + u^2), asin: u' - g' w with w = 1/v, v = sqrt(1 - g^2),
//    acos: u' + g' w, atan: u' - g' w with w = 1/(1 + g^2), log: u' - g' r
//    with r = 1/g, tanh: u' - g'(1 - u^2). g' is the total time derivative of
//    the recast argument (nested functions compose: sin(exp(x))).
//    These auxiliaries are fixed only up to a constant: their equations drop
//    the constant-term balance and a point condition pins them at t = 0 to
//    their definition (METHOD.md eq. 24), u(0) = exp(g(0)).
//  - cos(k.w t + phase), sin(...) with integer k are forcing: they become the
//    core's time functions, never auxiliaries.
//  - identical subexpressions are recast once (memo on the expression and on
//    the recast argument of every rule).
//  - a transcendental function of the top derivative (sin(x') in a first-order
//    equation) needs x'': the chain grows by one state (x_d1) for it.
// Variable order: the user variables with their derivative chains (x, x_d1,
// y, y_d1, ...), then the auxiliaries in order of creation (reproducible:
// operands are visited in the order of their printed form, not GiNaC's
// hash order). Auxiliary names say what they hold: sin_x, inv_R, sqrt_1,
// den_1 (a named denominator), pow_x, ...
//
// Errors (unknown parameter override, a base frequency <= 0, explicit time
// outside harmonic forcing, an unknown base frequency in a coefficient, ...)
// throw ModelError pointing at the equation concerned.

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "rmhb/collocation_residual.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/harmonic_solution.h"
#include "rmhb/model/model_definition.h"
#include "rmhb/model/original_system.h"

namespace rmhb::model {

struct RecastResult {
  std::string model_name;
  std::string source;          // the model's file name, for error messages
  ParameterValues parameters;  // the values used (defaults with overrides)
  // System, base frequencies (values or guesses), unknown flags, conditions:
  // the user's conditions first, then the pinning conditions.
  HarmonicBalanceProblem problem;
  // "sin_theta = sin(theta)": one line per auxiliary, in variable order.
  std::vector<std::string> definitions;
  int degree = 0;  // phi, PolynomialSystem::Degree()
  int num_user_conditions = 0;
  // Parameter -> base index: the parameters a known base frequency is bound
  // to (`frequencies: [w]`) whose value enters `problem` only as
  // problem.frequencies[base] (METHOD.md s.19). Decided on the symbols: the
  // recast keeps a base symbolic until an expression becomes a number, and
  // no coefficient, condition, pointwise equation or auxiliary definition
  // of `problem` contained it (nor explicit time, nor a forcing recognised
  // numerically). Then Recast(model, overrides with another value v of
  // it).problem is `problem` with frequencies[base] = v, to the last bit.
  // (original_problem is not covered.)
  std::map<std::string, int> frequency_parameters;

  // The model's equations as written, for harmonic balance without the
  // recast (HB-AFT, METHOD.md s.13): the user variables and their
  // derivative chains (the recast's first variables and chain equations,
  // same names and order), each user equation evaluated pointwise with its
  // exact partial derivatives (compiled), the user's conditions. Fewer
  // unknowns than the recast (no auxiliaries) and no recast truncation, but
  // no alias-free sample count. Empty, with the reason in
  // original_problem_error, when a user equation has explicit time with an
  // unknown base or several bases, or the unknown base frequency itself.
  std::optional<HarmonicBalanceProblem> original_problem;
  std::string original_problem_error;
  // x -> -x for every variable with t -> t + T/2, when every equation of
  // original_problem is invariant under it (checked numerically on the
  // compiled equations): a solution from a guess with only odd harmonics
  // keeps only odd harmonics (rmhb/symmetry.h). Not imposed here.
  std::optional<HalfTurnSymmetry> original_half_wave;

  // The original equations for the integrators; empty (with the reason in
  // original_error) when the model is not an explicit ODE.
  std::optional<OriginalSystem> original;
  std::string original_error;
  // The model's initial_state (or, without one, the conditions when they give
  // every state), in the order of original->state_names.
  std::optional<std::vector<double>> initial_state;

  // The guess of every recast variable as a function of the torus angles
  // theta_i = w_i t (the model's guess sampled, auxiliaries from their
  // definitions). Variables without a guess are 0.
  std::function<Eigen::VectorXd(const std::vector<double>& theta)> guess;
  // Every recast variable at torus angles theta from the user variables and
  // their time derivatives, `user` = (x, x', ..., x^(user_derivatives[0]),
  // y, y', ...): states read off, auxiliaries from their definitions. How a
  // guess measured on a trajectory reaches the auxiliaries
  // (rmhb/seeding/identified_guess.h); `guess` is this on the guessed values.
  std::function<Eigen::VectorXd(const std::vector<double>& theta, const std::vector<double>& user)>
      variables_from_user;
  std::vector<int> user_derivatives;  // per user variable, its highest derivative in `user`

  // The guess projected on the basis MakeBasis gives for `order`. Throws
  // ModelError if the guess is not finite somewhere (e.g. log of a negative
  // guessed value).
  HarmonicSolution InitialGuess(int order, BasisShape shape = BasisShape::kDiamond) const;
  HarmonicSolution InitialGuess(const HarmonicBasis& basis) const;

  // Readable recast: parameters, frequencies, variables with definitions,
  // equations, degree phi and conditions.
  std::string Report() const;
};

// `problem_only`: `problem` (with its definitions), the guess and
// frequency_parameters alone, without original_problem, the original
// system and initial_state (about half the work: their tapes), for callers
// that rebuild the problem at many parameter values (continuation, METHOD.md
// s.19). `problem` is the same as the full recast's; an initial_state the
// model cannot evaluate at these values is then not an error.
RecastResult Recast(const ModelDefinition& model, const ParameterValues& overrides = {}, bool problem_only = false);

}  // namespace rmhb::model

#endif  // RMHB_MODEL_RECAST_H_

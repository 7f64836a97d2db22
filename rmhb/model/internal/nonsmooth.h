#ifndef RMHB_MODEL_INTERNAL_NONSMOOTH_H_
#define RMHB_MODEL_INTERNAL_NONSMOOTH_H_

// The piecewise-smooth primitives of model files (METHOD.md s.15). Every
// function a user may write reduces to three GiNaC functions with a switch
// at zero argument:
//   ramp(g) = max(g, 0)   (derivative heaviside(g)),
//   heaviside(g) = 1 for g >= 0, else 0   (derivative 0 almost everywhere),
//   sgn(g) = -1, 0, 1   (derivative 0 almost everywhere),
// so that abs(g) = g sgn(g), max(a, b) = b + ramp(a - b), min(a, b) =
// a - ramp(a - b), clamp(x, lo, hi) = lo + ramp(x - lo) - ramp(x - hi).
// GiNaC differentiates them (the pointwise equations' exact partials, the
// Jacobian of harmonic balance), the tape evaluates them (CompiledFunction
// ops kRamp, kHeaviside, kSign) either by the argument's sign or in a frozen
// mode for event-located integration, where each argument is a switching
// surface.
//
// The set-valued Coulomb law coulomb(v, Fn, eps) (a friction force Fn sign(v),
// anything in [-Fn, Fn] while v = 0) is a fourth function: harmonic balance
// replaces it by the dynamic Lagrangian of its equation (DynamicLagrangian),
// the integrators by a stick phase.

#include <vector>

#include <ginac/ginac.h>

namespace rmhb::model::internal {

DECLARE_FUNCTION_1P(ramp)
DECLARE_FUNCTION_1P(heaviside)
DECLARE_FUNCTION_1P(sgn)
// coulomb(v, Fn, eps): eps the Lagrangian's penalty, 0 for automatic.
DECLARE_FUNCTION_3P(coulomb)

// Whether e contains ramp, heaviside, sgn or coulomb.
bool HasNonSmooth(const GiNaC::ex& e);
bool HasCoulomb(const GiNaC::ex& e);

// min(a, b), max(a, b), abs(g), clamp(x, lo, hi) in the primitives.
GiNaC::ex Max(const GiNaC::ex& a, const GiNaC::ex& b);
GiNaC::ex Min(const GiNaC::ex& a, const GiNaC::ex& b);
GiNaC::ex Abs(const GiNaC::ex& g);
GiNaC::ex Clamp(const GiNaC::ex& x, const GiNaC::ex& lo, const GiNaC::ex& hi);

// The dynamic Lagrangian (Nacivet et al. 2003, velocity form) of an
// equation e = e0 + c coulomb(v, Fn) = 0, c free of the coulomb term: the
// force the rest of the equation asks for, lambda_u = -e0 / c, is corrected
// by the penalty eps v and projected on the admissible set [-Fn, Fn],
//   lambda = clamp(lambda_u + eps v, -Fn, Fn),   result e0 + c lambda.
// Stuck samples (|lambda_u + eps v| < Fn) then contribute c eps v (the
// velocity must vanish), sliding ones e0 + c Fn sign (the equation with the
// Coulomb force). Throws std::invalid_argument (the message says why) when
// the coulomb term is not linear in e or appears more than once.
// `automatic_eps` is used when the term's own eps is 0.
//
// A friction force between two bodies enters two equations (with opposite
// signs) and is one force: `owner` is the first equation that holds the
// same coulomb term (e itself when e is), and lambda_u comes from it, so
// every equation holding the term sees the same lambda. Stuck, the owner
// then says v = 0 and the others e0_i - (c_i / c_owner) e0_owner = 0 (for
// two masses: the sum of their equations, the stuck pair's dynamics).
GiNaC::ex DynamicLagrangian(const GiNaC::ex& e, const GiNaC::ex& owner, const GiNaC::ex& automatic_eps);

// The coulomb terms of `equations` shared: coulomb(-v, Fn) is rewritten
// -coulomb(v, Fn) where coulomb(v, Fn) appeared first (the force is odd in
// v), so that the two sides of one contact name one term.
void ShareCoulombTerms(std::vector<GiNaC::ex>* equations);
// The first of `equations` holding `term` (a coulomb() call).
int CoulombOwner(const std::vector<GiNaC::ex>& equations, const GiNaC::ex& term);

}  // namespace rmhb::model::internal

#endif  // RMHB_MODEL_INTERNAL_NONSMOOTH_H_

#include "rmhb/model/internal/nonsmooth.h"

#include <stdexcept>

namespace rmhb::model::internal {

using GiNaC::ex;
using GiNaC::numeric;

namespace {

ex RampEval(const ex& x) {
  if (GiNaC::is_a<numeric>(x) && GiNaC::ex_to<numeric>(x).is_real())
    return GiNaC::ex_to<numeric>(x).is_positive() ? x : ex(0);
  return ramp(x).hold();
}
ex RampDerivative(const ex& x, unsigned) { return heaviside(x); }

ex HeavisideEval(const ex& x) {
  if (GiNaC::is_a<numeric>(x) && GiNaC::ex_to<numeric>(x).is_real())
    return GiNaC::ex_to<numeric>(x).is_negative() ? ex(0) : ex(1);
  return heaviside(x).hold();
}
ex ZeroDerivative(const ex&, unsigned) { return 0; }

ex SgnEval(const ex& x) {
  if (GiNaC::is_a<numeric>(x) && GiNaC::ex_to<numeric>(x).is_real())
    return GiNaC::ex_to<numeric>(x).is_zero() ? 0 : GiNaC::ex_to<numeric>(x).is_positive() ? 1 : -1;
  return sgn(x).hold();
}

ex CoulombEval(const ex& v, const ex& f, const ex& eps) { return coulomb(v, f, eps).hold(); }
ex CoulombDerivative(const ex&, const ex&, const ex&, unsigned) {
  throw std::invalid_argument("coulomb() is set-valued: it has no derivative");
}

}  // namespace

REGISTER_FUNCTION(ramp, eval_func(RampEval).derivative_func(RampDerivative))
REGISTER_FUNCTION(heaviside, eval_func(HeavisideEval).derivative_func(ZeroDerivative))
REGISTER_FUNCTION(sgn, eval_func(SgnEval).derivative_func(ZeroDerivative))
REGISTER_FUNCTION(coulomb, eval_func(CoulombEval).derivative_func(CoulombDerivative))

bool HasNonSmooth(const ex& e) {
  return e.has(ramp(GiNaC::wild())) || e.has(heaviside(GiNaC::wild())) || e.has(sgn(GiNaC::wild())) ||
         HasCoulomb(e);
}

bool HasCoulomb(const ex& e) { return e.has(coulomb(GiNaC::wild(0), GiNaC::wild(1), GiNaC::wild(2))); }

ex Max(const ex& a, const ex& b) { return b + ramp(a - b); }
ex Min(const ex& a, const ex& b) { return a - ramp(a - b); }
ex Abs(const ex& g) { return g * sgn(g); }
ex Clamp(const ex& x, const ex& lo, const ex& hi) { return lo + ramp(x - lo) - ramp(x - hi); }

ex DynamicLagrangian(const ex& e, const ex& automatic_eps) {
  GiNaC::exset found;
  e.find(coulomb(GiNaC::wild(0), GiNaC::wild(1), GiNaC::wild(2)), found);
  if (found.size() != 1)
    throw std::invalid_argument("an equation may hold one coulomb() term (found " +
                                std::to_string(found.size()) + ")");
  const ex term = *found.begin();
  const GiNaC::symbol placeholder("coulomb_force");
  const ex expanded = e.subs(term == placeholder).expand();
  const ex c = expanded.coeff(placeholder, 1);
  const ex e0 = expanded.coeff(placeholder, 0);
  if (expanded.degree(placeholder) != 1 || c.has(placeholder) || HasCoulomb(c) || HasCoulomb(e0) ||
      c.is_zero())
    throw std::invalid_argument("coulomb() must enter its equation linearly (a force added to it)");
  const ex v = term.op(0), fn = term.op(1);
  const ex eps = term.op(2).is_zero() ? automatic_eps : term.op(2);
  const ex lambda = Clamp(-e0 / c + eps * v, -fn, fn);
  return e0 + c * lambda;
}

}  // namespace rmhb::model::internal

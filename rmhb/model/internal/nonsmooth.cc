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

namespace {

// The one coulomb() term of e (std::invalid_argument when there are several).
ex TheCoulombTerm(const ex& e) {
  GiNaC::exset found;
  e.find(coulomb(GiNaC::wild(0), GiNaC::wild(1), GiNaC::wild(2)), found);
  if (found.size() != 1)
    throw std::invalid_argument("an equation may hold one coulomb() term (found " +
                                std::to_string(found.size()) + ")");
  return *found.begin();
}

// e = e0 + c term, c free of coulomb terms (std::invalid_argument otherwise).
void SplitLinear(const ex& e, const ex& term, ex* e0, ex* c) {
  const GiNaC::symbol placeholder("coulomb_force");
  const ex expanded = e.subs(term == placeholder).expand();
  *c = expanded.coeff(placeholder, 1);
  *e0 = expanded.coeff(placeholder, 0);
  if (expanded.degree(placeholder) != 1 || c->has(placeholder) || HasCoulomb(*c) || HasCoulomb(*e0) ||
      c->is_zero())
    throw std::invalid_argument("coulomb() must enter its equation linearly (a force added to it)");
}

}  // namespace

ex DynamicLagrangian(const ex& e, const ex& owner, const ex& automatic_eps) {
  const ex term = TheCoulombTerm(e);
  if (TheCoulombTerm(owner) != term) throw std::invalid_argument("the owner equation holds another coulomb() term");
  ex e0, c, o0, oc;
  SplitLinear(e, term, &e0, &c);
  SplitLinear(owner, term, &o0, &oc);
  const ex v = term.op(0), fn = term.op(1);
  const ex eps = term.op(2).is_zero() ? automatic_eps : term.op(2);
  const ex lambda = Clamp(-o0 / oc + eps * v, -fn, fn);
  return e0 + c * lambda;
}

void ShareCoulombTerms(std::vector<ex>* equations) {
  std::vector<ex> seen;
  for (ex& e : *equations) {
    GiNaC::exset found;
    e.find(coulomb(GiNaC::wild(0), GiNaC::wild(1), GiNaC::wild(2)), found);
    GiNaC::exmap mirrored;
    for (const ex& t : found) {
      bool matched = false;
      for (const ex& s : seen) {
        if (s == t) matched = true;
        else if ((s.op(0) + t.op(0)).expand().is_zero() && s.op(1) == t.op(1) && s.op(2) == t.op(2))
          mirrored[t] = -s, matched = true;
        if (matched) break;
      }
      if (!matched) seen.push_back(t);
    }
    if (!mirrored.empty()) e = e.subs(mirrored, GiNaC::subs_options::no_pattern);
  }
}

int CoulombOwner(const std::vector<ex>& equations, const ex& term) {
  for (std::size_t i = 0; i < equations.size(); ++i)
    if (equations[i].has(term)) return static_cast<int>(i);
  return -1;
}

}  // namespace rmhb::model::internal

#ifndef RMHB_POLYNOMIAL_SYSTEM_H_
#define RMHB_POLYNOMIAL_SYSTEM_H_

// A polynomial differential-algebraic system in implicit form
//   g_i(t, z, z') = 0,  i = 0..n-1,
// polynomial in the states z and their first derivatives z'. Implicit form
// keeps second derivatives inside nonlinear terms (asymmetric pendulum) and
// algebraic constraints (u^2 + v^2 - 1 = 0) without special cases.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rmhb/polynomial.h"

namespace rmhb {

enum class VariableRole {
  kState,      // a variable of the user's original equations (or its derivative)
  kAuxiliary,  // introduced by the recast (s = sin(theta), u = 1/R, ...)
};

struct Variable {
  std::string name;
  VariableRole role = VariableRole::kState;
  std::string definition;  // for auxiliaries, e.g. "sin(theta)"; documentation only
};

// An equation evaluated pointwise at the samples instead of as a polynomial:
// the model's equation as written, sin(theta) and (1 - x'^2)^(3/2) included
// (HB-AFT on the original equations, METHOD.md s.13). Its value and its
// partial derivatives in `slots` come from `evaluate` at each sample. No
// finite sample count is alias-free for it (a non-polynomial term has
// harmonics of every order); the samples are chosen well above the basis
// and the solution is checked on a finer grid (HarmonicBalanceSummary::
// alias_check).
struct PointwiseEquation {
  std::vector<Slot> slots;  // the inputs after t, in this order
  // in: t, the slot values, then the base frequencies; out: the value, then
  // d/d(slot) for every slot. Must be callable from several threads.
  std::function<void(const double* in, double* out)> evaluate;
  // Optional, the same at `count` points at once: input k of point t at
  // in[k * in_stride + t], output i at out[i * out_stride + t]. The
  // collocation residual takes it for all its samples in one call.
  std::function<void(long count, const double* in, long in_stride, double* out, long out_stride)>
      evaluate_many;
  std::string text;  // as the user wrote it, for reports
  // How the equation transforms when every variable changes sign and t
  // moves by half the period of one base (x -> -x, t -> t + T/2): -1 or +1
  // when known to be invariant (HalfTurnSymmetry::EquationSign), 0 not.
  int half_wave_sign = 0;
  // Piecewise smooth (max, abs, sign, ..., a Coulomb Lagrangian: METHOD.md
  // s.15): its spectrum decays algebraically, so it needs far more samples
  // than a smooth pointwise equation (SamplesForRule).
  bool nonsmooth = false;
};

struct Equation {
  Polynomial lhs;  // lhs = 0 (zero when pointwise)
  // A variable defined only through its derivative (s' = c v for s = sin(theta))
  // is fixed up to a constant. The paper (METHOD.md s.4, eq. 24) drops the
  // constant-term balance of such an equation and pins the value at t = 0
  // with a condition instead.
  bool balance_constant = true;
  std::shared_ptr<const PointwiseEquation> pointwise;  // set: evaluated pointwise, lhs unused
};

class PolynomialSystem {
 public:
  int AddVariable(const std::string& name, VariableRole role = VariableRole::kState,
                  const std::string& definition = "");
  int AddEquation(Polynomial lhs, bool balance_constant = true);
  int AddPointwiseEquation(PointwiseEquation equation);
  // Whether any equation is pointwise: then no sample count is alias-free
  // and Degree(), ForcingReach() and AliasFreeSamples() describe the
  // polynomial equations only.
  bool HasPointwise() const;
  bool HasNonSmooth() const;  // a pointwise equation is piecewise smooth

  // Convenience for the builder API: sys.Var("x") or sys.Var(0).
  Polynomial Var(int j) const;
  Polynomial Var(const std::string& name) const;
  Polynomial D(const std::string& name) const;
  int IndexOf(const std::string& name) const;  // -1 if absent

  int num_variables() const { return static_cast<int>(variables_.size()); }
  int num_equations() const { return static_cast<int>(equations_.size()); }
  const std::vector<Variable>& variables() const { return variables_; }
  const std::vector<Equation>& equations() const { return equations_; }
  std::vector<std::string> names() const;

  // phi: the polynomial degree, z' counted like z.
  int Degree() const;
  // Largest |harmonic| along base `base` of any explicit time function.
  int ForcingReach(int base) const;
  // Smallest number of samples along base `base` such that collocation with
  // `reach` harmonics along that base is alias-free (Theorem 1, extended to
  // forcing): M > max over terms of (degree + 1) reach + forcing reach.
  int AliasFreeSamples(int reach, int base = 0) const;
  // Throws std::invalid_argument naming the problem if the system is not
  // square or references a variable that does not exist.
  void Validate() const;

  std::string ToString() const;

 private:
  std::vector<Variable> variables_;
  std::vector<Equation> equations_;
};

}  // namespace rmhb

#endif  // RMHB_POLYNOMIAL_SYSTEM_H_

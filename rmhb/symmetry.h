#ifndef RMHB_SYMMETRY_H_
#define RMHB_SYMMETRY_H_

// Half-turn symmetries of a (quasi-)periodic solution, and what they save.
//
// Many systems are odd: z -> -z maps solutions to solutions (Duffing, Van der
// Pol with its forcing shifted by half a period, the pendulums). On a torus
// such a symmetry acts as a shift of the angles combined with sign flips,
//   z_j(theta + pi h) = s_j z_j(theta),   h in {0,1}^d, s_j = +-1,
// and a solution that has it contains only harmonics k with (-1)^(k.h) = s_j
// in variable j (half-wave symmetry: odd harmonics only). Imposing it drops
// the other coefficients, which would stay zero anyway, from the unknowns,
// and their balance equations, which then hold identically, from the
// residuals. Each independent symmetry halves the unknowns and cuts the
// dense factorisation that dominates a large solve by about 8.
//
// Which symmetries the solution has is a property of the solution, not only
// of the system (a symmetric system can have asymmetric solutions): the
// caller asserts it, e.g. because the initial state is symmetric; a wrong
// assertion shows as a solve that does not converge or a trajectory check
// that fails. What can be checked here is that the system is invariant.

#include <string>
#include <vector>

#include "rmhb/polynomial_system.h"

namespace rmhb {

struct HalfTurnSymmetry {
  std::vector<int> half_turn;  // h_b in {0, 1}, one per base frequency
  std::vector<int> sign;       // s_j = +1 or -1, one per variable
  std::string description;     // e.g. "x -> -x with theta_1 + pi"

  // (-1)^(k.h): how harmonic k transforms under the shift.
  int Parity(const std::vector<int>& harmonic) const;
  // Whether harmonic k may appear in a function that transforms with `sign`.
  bool Allows(const std::vector<int>& harmonic, int sign) const { return Parity(harmonic) == sign; }

  // The sign with which equation `equation` of `system` transforms: every
  // monomial must give the same one (variables and derivatives by their
  // sign, forcing cos/sin(q.theta) by (-1)^(q.h)). Throws
  // std::invalid_argument naming the equation when it mixes parities (the
  // system does not have this symmetry) or when the sizes do not fit.
  int EquationSign(const PolynomialSystem& system, int equation, int num_bases) const;
};

}  // namespace rmhb

#endif  // RMHB_SYMMETRY_H_

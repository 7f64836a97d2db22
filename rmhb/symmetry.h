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

#include "rmhb/harmonic_solution.h"
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
  // The same for a polynomial equation without the checks: 0 when its
  // terms mix parities.
  int PolynomialSign(const PolynomialSystem& system, int equation, int num_bases) const;
  // The map as bits (half-turns, then flipped variables): composing two maps
  // is the xor of their masks.
  unsigned long Mask() const;
};

// The half-turn symmetries of a polynomial system (every equation keeps one
// parity): every element of the group they form but the identity (at most
// 255), e.g. for two coupled pendula (x, y) -> -(x, y) with both angles
// turned, and x -> -x with the first. Empty for pointwise equations or more
// than 14 variables (the search is over 2^(bases + variables) candidates).
// Which of them a solution has, and an independent set of those, is the
// caller's to decide (ImposeGuessSymmetries).
std::vector<HalfTurnSymmetry> DetectHalfTurnSymmetries(const PolynomialSystem& system, int num_bases);

// Those of `candidates` that `guess` has -- its harmonics of the other
// parity at most `tolerance` times its largest coefficient, some flipped variable
// not zero and some odd harmonic along every turned base (a constant or a
// guess at rest has every symmetry trivially) -- leaving out compositions of those chosen and of `already`:
// an independent set to impose (HarmonicBalanceProblem::symmetries).
// Imposing them is exact: the equations are equivariant, so Newton's
// iterates from a symmetric guess stay symmetric.
std::vector<HalfTurnSymmetry> SymmetriesOf(const HarmonicSolution& guess, const std::vector<HalfTurnSymmetry>& candidates,
                                           const std::vector<HalfTurnSymmetry>& already = {},
                                           double tolerance = 1e-14);

}  // namespace rmhb

#endif  // RMHB_SYMMETRY_H_

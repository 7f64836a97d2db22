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
//
// A time reversal theta -> -theta (reverses_time) splits each harmonic
// instead: an even solution has its cosines only, an odd one its sines
// (DetectTimeReversals; METHOD.md s.8).

#include <string>
#include <vector>

#include "rmhb/harmonic_solution.h"
#include "rmhb/point_condition.h"
#include "rmhb/polynomial_system.h"

namespace rmhb {

struct HalfTurnSymmetry {
  std::vector<int> half_turn;  // h_b in {0, 1}, one per base frequency
  std::vector<int> sign;       // s_j = +1 or -1, one per variable
  std::string description;     // e.g. "x -> -x with theta_1 + pi"
  // A time reversal theta -> -theta (with the half-turn, if any): a solution
  // with z_j(-theta) = s_j z_j(theta) has cosines only (and its constant)
  // where s_j = +1, sines only where s_j = -1 (METHOD.md s.8). Derivatives
  // change sign once more per order, and so do sin(q.theta) forcing terms.
  bool reverses_time = false;
  // With reverses_time: each equation's sign, found by DetectTimeReversals
  // (the pointwise ones numerically, so EquationSign cannot recompute it).
  std::vector<int> equation_sign = {};

  // (-1)^(k.h): how harmonic k transforms under the shift. Inline: a
  // residual's set-up asks it for every coefficient of every variable and
  // equation (a tenth of the construction when it was a call).
  int Parity(const std::vector<int>& harmonic) const {
    long dot = 0;
    for (size_t b = 0; b < harmonic.size() && b < half_turn.size(); ++b) dot += long(harmonic[b]) * half_turn[b];
    return dot % 2 == 0 ? 1 : -1;
  }
  // Whether harmonic k may appear in a function that transforms with `sign`.
  bool Allows(const std::vector<int>& harmonic, int sign) const { return Parity(harmonic) == sign; }
  // The same for one coefficient of harmonic k, its sine (`sine`) or its
  // cosine (or the constant): they differ only under a time reversal.
  bool AllowsCoefficient(const std::vector<int>& harmonic, bool sine, int sign) const {
    return (reverses_time && sine ? -Parity(harmonic) : Parity(harmonic)) == sign;
  }
  // The same for coefficient c of a variable's row on `basis` (the layout of
  // HarmonicSolution: c = 0 the constant, 2k - 1 and 2k harmonic k's cosine
  // and sine).
  bool AllowsCoefficient(const HarmonicBasis& basis, int c, int sign) const {
    return AllowsCoefficient(basis.harmonic((c + 1) / 2), c > 0 && c % 2 == 0, sign);
  }

  // The sign with which equation `equation` of `system` transforms: every
  // monomial must give the same one (variables and derivatives by their
  // sign, forcing cos/sin(q.theta) by (-1)^(q.h)). Throws
  // std::invalid_argument naming the equation when it mixes parities (the
  // system does not have this symmetry) or when the sizes do not fit.
  int EquationSign(const PolynomialSystem& system, int equation, int num_bases) const;
  // The same for a polynomial equation without the checks: 0 when its
  // terms mix parities.
  int PolynomialSign(const PolynomialSystem& system, int equation, int num_bases) const;
  // How z_j^(d) transforms: s_j, and once more per derivative under a reversal.
  int SlotSign(const Slot& slot) const {
    return reverses_time && slot.derivative % 2 == 1 ? -sign[slot.variable] : sign[slot.variable];
  }
  // The map as bits (half-turns, then flipped variables, then the time
  // reversal): composing two maps is the xor of their masks.
  unsigned long Mask() const;
};

// How a pointwise equation g(t, z) transforms under t -> mirror t + shift,
// z_i -> slot_sign[i] z_i (the base frequencies `frequencies` held): +1 or -1
// when g maps to +-g at six points within the domain of the usual
// nonlinearities (|z| <= 1/2), 0 when it does not (or is not finite there).
// The half-wave map is mirror 1, shift T/2, every sign -1; a time reversal
// mirror -1, shift 0.
int PointwiseEquationSign(const PointwiseEquation& e, const std::vector<double>& frequencies, double mirror,
                          double shift, const std::vector<int>& slot_sign);

// The time reversals of `system` (t -> -t with z_j -> s_j z_j; one base or
// several, all reversed): every equation keeps one sign, the polynomial ones
// term by term, the pointwise ones at a few points with the base
// frequencies `frequencies` (e.g. x'' + (1 - x'^2)^(3/2) x = 0 under x -> -x,
// or the pendulum's with x -> x). Every sign pattern that works is listed
// (at most 64; the pendulum's x even and x odd both), the guess picks
// (SymmetriesOf); empty for more than 14 variables. A
// conservative oscillator released at rest (or launched from its centre)
// has one: its solution is even (or odd) in t, half the unknowns again.
std::vector<HalfTurnSymmetry> DetectTimeReversals(const PolynomialSystem& system,
                                                  const std::vector<double>& frequencies);

// What a condition at t = 0 is on the subspace of a pure time reversal
// (no half-turn), where z_j(0) = 0 for s_j = -1 and z_j'(0) = 0 for s_j = +1:
// kept (it reads a value that is free there), holding identically (it reads
// only zeros and is met: its row is dropped, e.g. x'(0) = 0 for an even x)
// or violated (it reads only zeros and is not met: no solution has the
// symmetry). A recast pin of a variable the symmetry flips (whose constant
// term the subspace drops) holds there too: implied, its row dropped. Any
// other condition is kept under a half-turn.
enum class ConditionOnSubspace { kKept, kHolds, kViolated };
ConditionOnSubspace ClassifyCondition(const HalfTurnSymmetry& symmetry, const PointCondition& condition);

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

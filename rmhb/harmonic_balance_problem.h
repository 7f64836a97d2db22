#ifndef RMHB_HARMONIC_BALANCE_PROBLEM_H_
#define RMHB_HARMONIC_BALANCE_PROBLEM_H_

// What the harmonic balance solves (rmhb/harmonic_balance.h): a polynomial
// differential-algebraic system (rmhb/polynomial_system.h, the recast of a
// model, METHOD.md s.4), its base frequencies, known or unknown, the point
// conditions that fix phases and amplitudes (METHOD.md s.5), asserted
// symmetries, and the definitions of recast auxiliaries for the physical check.

#include <vector>

#include "rmhb/definition_check.h"
#include "rmhb/point_condition.h"
#include "rmhb/polynomial_system.h"
#include "rmhb/symmetry.h"

namespace rmhb {

struct HarmonicBalanceProblem {
  PolynomialSystem system;
  // Base frequencies: their values, or initial guesses where unknown.
  std::vector<double> frequencies;
  std::vector<bool> unknown_frequency;  // empty: all known
  std::vector<PointCondition> conditions;
  // Symmetries the solution is asserted to have (see rmhb/symmetry.h).
  std::vector<HalfTurnSymmetry> symmetries = {};
  // The variables from their definitions (recast auxiliaries from the user
  // variables), when known: SolveHarmonicBalance then checks a converged
  // solution against them (rmhb/definition_check.h).
  VariableDefinitions definitions = {};

  int num_unknown_frequencies() const;
  // Throws std::invalid_argument naming what is wrong.
  void Validate() const;
};

// The symmetries of the problem's equations that a solution can be held to
// with its conditions (METHOD.md s.8): half-turns when there are several
// bases or no conditions but recast pins (one base's half-turn moves t = 0
// to T/2, where a user's condition need not hold: Kepler's ellipse from a
// circular guess failed), time reversals unless their subspace violates a
// condition.
// Whether a solution has one is SymmetriesOf's to tell.
bool HalfTurnsKeepConditions(const HarmonicBalanceProblem& problem);
// Whether no condition is violated on the symmetry's subspace (ClassifyCondition).
bool ViolatesNoCondition(const HalfTurnSymmetry& symmetry, const std::vector<PointCondition>& conditions);
std::vector<HalfTurnSymmetry> ImposableSymmetries(const HarmonicBalanceProblem& problem);

}  // namespace rmhb

#endif  // RMHB_HARMONIC_BALANCE_PROBLEM_H_

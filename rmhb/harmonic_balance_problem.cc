#include "rmhb/harmonic_balance_problem.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rmhb {

int HarmonicBalanceProblem::num_unknown_frequencies() const {
  int n = 0;
  for (bool u : unknown_frequency) n += u;
  return n;
}

void HarmonicBalanceProblem::Validate() const {
  system.Validate();
  if (frequencies.empty()) throw std::invalid_argument("no base frequency given");
  for (double w : frequencies)
    if (!std::isfinite(w) || w <= 0)
      throw std::invalid_argument("base frequencies must be finite and > 0, got " +
                                  std::to_string(w));
  if (!unknown_frequency.empty() && unknown_frequency.size() != frequencies.size())
    throw std::invalid_argument("unknown_frequency must have one flag per base frequency");
  for (const auto& symmetry : symmetries) {
    for (int i = 0; i < system.num_equations(); ++i)
      symmetry.EquationSign(system, i, static_cast<int>(frequencies.size()));
    for (const PointCondition& condition : conditions)
      if (ClassifyCondition(symmetry, condition) == ConditionOnSubspace::kViolated)
        throw std::invalid_argument("condition '" + condition.description + "' cannot hold under the symmetry '" +
                                    symmetry.description + "'");
  }
}

bool HalfTurnsKeepConditions(const HarmonicBalanceProblem& problem) {
  if (problem.frequencies.size() > 1) return true;
  for (const PointCondition& c : problem.conditions)
    if (c.pinned_variable < 0) return false;
  return true;  // none, or recast pins only (equivariant: rmhb/point_condition.h)
}

std::vector<HalfTurnSymmetry> ImposableSymmetries(const HarmonicBalanceProblem& problem) {
  std::vector<HalfTurnSymmetry> found;
  if (HalfTurnsKeepConditions(problem))
    found = DetectHalfTurnSymmetries(problem.system, static_cast<int>(problem.frequencies.size()));
  for (HalfTurnSymmetry& reversal : DetectTimeReversals(problem.system, problem.frequencies))
    if (ViolatesNoCondition(reversal, problem.conditions)) found.push_back(std::move(reversal));
  return found;
}

bool ViolatesNoCondition(const HalfTurnSymmetry& symmetry, const std::vector<PointCondition>& conditions) {
  for (const PointCondition& c : conditions)
    if (ClassifyCondition(symmetry, c) == ConditionOnSubspace::kViolated) return false;
  return true;
}

}  // namespace rmhb

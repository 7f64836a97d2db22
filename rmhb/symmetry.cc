#include "rmhb/symmetry.h"

#include <stdexcept>

namespace rmhb {

int HalfTurnSymmetry::Parity(const std::vector<int>& k) const {
  long dot = 0;
  for (size_t b = 0; b < k.size() && b < half_turn.size(); ++b) dot += long(k[b]) * half_turn[b];
  return dot % 2 == 0 ? 1 : -1;
}

int HalfTurnSymmetry::EquationSign(const PolynomialSystem& system, int equation,
                                   int num_bases) const {
  const std::string name = description.empty() ? "half-turn symmetry" : "symmetry '" + description + "'";
  if (static_cast<int>(half_turn.size()) != num_bases)
    throw std::invalid_argument(name + ": needs one half-turn flag per base frequency (" +
                                std::to_string(num_bases) + "), got " +
                                std::to_string(half_turn.size()));
  if (static_cast<int>(sign.size()) != system.num_variables())
    throw std::invalid_argument(name + ": needs one sign per variable (" +
                                std::to_string(system.num_variables()) + "), got " +
                                std::to_string(sign.size()));
  for (int h : half_turn)
    if (h != 0 && h != 1) throw std::invalid_argument(name + ": half-turn flags must be 0 or 1");
  for (int s : sign)
    if (s != 1 && s != -1) throw std::invalid_argument(name + ": signs must be +1 or -1");
  if (const auto& p = system.equations()[equation].pointwise) {
    // Known only for the half-wave map of one base with every sign flipped.
    bool all_flip = true;
    for (int s : sign) all_flip = all_flip && s == -1;
    if (num_bases != 1 || half_turn[0] != 1 || !all_flip || p->half_wave_sign == 0)
      throw std::invalid_argument("equation " + std::to_string(equation + 1) + " (evaluated pointwise) is not known "
                                  "to be invariant under the " + name);
    return p->half_wave_sign;
  }
  int result = 0;
  for (const auto& [mono, c] : system.equations()[equation].lhs.terms()) {
    int s = 1;
    for (const auto& [slot, power] : mono.factors)
      if (sign[slot.variable] < 0 && power % 2 == 1) s = -s;
    if (mono.time.kind != TimeFunction::Kind::kOne) {
      std::vector<int> q = mono.time.harmonic;
      q.resize(num_bases, 0);
      s *= Parity(q);
    }
    if (result == 0) result = s;
    if (s != result)
      throw std::invalid_argument("equation " + std::to_string(equation + 1) +
                                  " is not invariant under the " + name +
                                  ": its terms transform with different signs");
  }
  return result == 0 ? 1 : result;
}

}  // namespace rmhb

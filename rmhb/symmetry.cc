#include "rmhb/symmetry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rmhb {

int HalfTurnSymmetry::EquationSign(const PolynomialSystem& system, int equation,
                                   int num_bases) const {
  // Only for the messages: every residual's set-up validates its problem.
  auto name = [&] { return description.empty() ? std::string("half-turn symmetry") : "symmetry '" + description + "'"; };
  if (static_cast<int>(half_turn.size()) != num_bases)
    throw std::invalid_argument(name() + ": needs one half-turn flag per base frequency (" +
                                std::to_string(num_bases) + "), got " +
                                std::to_string(half_turn.size()));
  if (static_cast<int>(sign.size()) != system.num_variables())
    throw std::invalid_argument(name() + ": needs one sign per variable (" +
                                std::to_string(system.num_variables()) + "), got " +
                                std::to_string(sign.size()));
  for (int h : half_turn)
    if (h != 0 && h != 1) throw std::invalid_argument(name() + ": half-turn flags must be 0 or 1");
  for (int s : sign)
    if (s != 1 && s != -1) throw std::invalid_argument(name() + ": signs must be +1 or -1");
  if (reverses_time && static_cast<int>(equation_sign.size()) == system.num_equations()) {
    if (equation_sign[equation] == 0)
      throw std::invalid_argument("equation " + std::to_string(equation + 1) + " is not invariant under the " + name());
    return equation_sign[equation];
  }
  if (const auto& p = system.equations()[equation].pointwise) {
    // Known only for the half-wave map of one base with every sign flipped.
    bool all_flip = true;
    for (int s : sign) all_flip = all_flip && s == -1;
    if (num_bases != 1 || half_turn[0] != 1 || !all_flip || p->half_wave_sign == 0)
      throw std::invalid_argument("equation " + std::to_string(equation + 1) + " (evaluated pointwise) is not known "
                                  "to be invariant under the " + name());
    return p->half_wave_sign;
  }
  const int result = PolynomialSign(system, equation, num_bases);
  if (result == 0)
    throw std::invalid_argument("equation " + std::to_string(equation + 1) + " is not invariant under the " + name() +
                                ": its terms transform with different signs");
  return result;
}

int HalfTurnSymmetry::PolynomialSign(const PolynomialSystem& system, int equation, int num_bases) const {
  int result = 0;
  for (const auto& [mono, c] : system.equations()[equation].lhs.terms()) {
    int s = 1;
    for (const auto& [slot, power] : mono.factors)
      if (SlotSign(slot) < 0 && power % 2 == 1) s = -s;
    if (mono.time.kind != TimeFunction::Kind::kOne) {
      std::vector<int> q = mono.time.harmonic;
      q.resize(num_bases, 0);
      s *= Parity(q);
      if (reverses_time && mono.time.kind == TimeFunction::Kind::kSin) s = -s;
    }
    if (result == 0) result = s;
    if (s != result) return 0;
  }
  return result == 0 ? 1 : result;
}

namespace {
std::string Describe(const PolynomialSystem& system, const HalfTurnSymmetry& s) {
  std::string flipped, turned;
  for (size_t j = 0; j < s.sign.size(); ++j)
    if (s.sign[j] < 0) flipped += (flipped.empty() ? "" : ", ") + system.variables()[j].name;
  for (size_t b = 0; b < s.half_turn.size(); ++b)
    if (s.half_turn[b]) turned += (turned.empty() ? "theta_" : " + theta_") + std::to_string(b + 1);
  if (s.reverses_time)
    return std::string("t -> -t") + (flipped.empty() ? "" : " with (" + flipped + ") -> -(" + flipped + ")") +
           " (time reversal, detected)";
  return (flipped.empty() ? std::string("no sign change") : "(" + flipped + ") -> -(" + flipped + ")") +
         (turned.empty() ? "" : " with " + turned + " + pi") + " (detected)";
}
}  // namespace

unsigned long HalfTurnSymmetry::Mask() const {
  unsigned long mask = 0;
  for (size_t b = 0; b < half_turn.size(); ++b) mask |= static_cast<unsigned long>(half_turn[b] != 0) << b;
  for (size_t j = 0; j < sign.size(); ++j) mask |= static_cast<unsigned long>(sign[j] < 0) << (half_turn.size() + j);
  return mask | static_cast<unsigned long>(reverses_time) << (half_turn.size() + sign.size());
}

std::vector<HalfTurnSymmetry> DetectHalfTurnSymmetries(const PolynomialSystem& system, int num_bases) {
  const int n = system.num_variables();
  std::vector<HalfTurnSymmetry> found;
  if (n > 14 || num_bases > 4 || system.HasPointwise()) return found;
  // The invariant maps form a group (bit masks under xor): find generators,
  // then list every element but the identity.
  std::vector<unsigned long> group = {0};
  const unsigned long total = 1UL << (num_bases + n);
  for (unsigned long mask = 1; mask < total && group.size() < 256; ++mask) {
    if (std::find(group.begin(), group.end(), mask) != group.end()) continue;
    HalfTurnSymmetry s;
    for (int b = 0; b < num_bases; ++b) s.half_turn.push_back(mask >> b & 1);
    for (int j = 0; j < n; ++j) s.sign.push_back(mask >> (num_bases + j) & 1 ? -1 : 1);
    bool invariant = true;
    for (int i = 0; i < system.num_equations() && invariant; ++i)
      invariant = s.PolynomialSign(system, i, num_bases) != 0;
    if (!invariant) continue;
    const size_t size = group.size();
    for (size_t g = 0; g < size; ++g) group.push_back(group[g] ^ mask);
  }
  std::sort(group.begin(), group.end());
  for (unsigned long mask : group) {
    if (mask == 0) continue;
    HalfTurnSymmetry s;
    for (int b = 0; b < num_bases; ++b) s.half_turn.push_back(mask >> b & 1);
    for (int j = 0; j < n; ++j) s.sign.push_back(mask >> (num_bases + j) & 1 ? -1 : 1);
    s.description = Describe(system, s);
    found.push_back(std::move(s));
  }
  return found;
}

int PointwiseEquationSign(const PointwiseEquation& e, const std::vector<double>& frequencies, double mirror,
                          double shift, const std::vector<int>& slot_sign) {
  const std::size_t n = e.slots.size(), d = frequencies.size();
  std::vector<double> in(1 + n + d), mapped(in.size()), out(1 + n), out_mapped(1 + n);
  int sign = 0;
  for (int point = 0; point < 6; ++point) {
    in[0] = 0.37 + 1.3 * point;
    mapped[0] = mirror * in[0] + shift;
    for (std::size_t i = 0; i < n; ++i) {
      in[1 + i] = 0.5 * std::sin(1.7 * point + 2.3 * double(i) + 0.4);
      mapped[1 + i] = slot_sign[i] * in[1 + i];
    }
    for (std::size_t b = 0; b < d; ++b) in[1 + n + b] = mapped[1 + n + b] = frequencies[b];
    e.evaluate(in.data(), out.data());
    e.evaluate(mapped.data(), out_mapped.data());
    const double a = out[0], b = out_mapped[0], tol = 1e-12 * (1 + std::abs(a));
    if (!std::isfinite(a) || !std::isfinite(b)) return 0;
    const int p = std::abs(a + b) <= tol ? -1 : std::abs(a - b) <= tol ? 1 : 0;
    if (p == 0 || (sign != 0 && p != sign && std::abs(a) > tol)) return 0;
    if (std::abs(a) > tol) sign = p;
  }
  return sign;
}

std::vector<HalfTurnSymmetry> DetectTimeReversals(const PolynomialSystem& system,
                                                  const std::vector<double>& frequencies) {
  const int n = system.num_variables(), d = static_cast<int>(frequencies.size());
  std::vector<HalfTurnSymmetry> found;
  if (n > 14 || d == 0) return found;
  for (unsigned long mask = 0; mask < (1UL << n) && found.size() < 64; ++mask) {
    HalfTurnSymmetry s;
    s.half_turn.assign(d, 0);
    s.reverses_time = true;
    for (int j = 0; j < n; ++j) s.sign.push_back(mask >> j & 1 ? -1 : 1);
    s.equation_sign.assign(system.num_equations(), 0);
    bool invariant = true;  // the polynomial equations first: cheap, and they prune
    for (int i = 0; i < system.num_equations() && invariant; ++i)
      if (!system.equations()[i].pointwise) invariant = (s.equation_sign[i] = s.PolynomialSign(system, i, d)) != 0;
    for (int i = 0; i < system.num_equations() && invariant; ++i)
      if (const auto& p = system.equations()[i].pointwise) {
        std::vector<int> slot_sign;
        for (const Slot& slot : p->slots) slot_sign.push_back(s.SlotSign(slot));
        invariant = (s.equation_sign[i] = PointwiseEquationSign(*p, frequencies, -1, 0, slot_sign)) != 0;
      }
    if (!invariant) continue;
    s.description = Describe(system, s);
    found.push_back(std::move(s));
  }
  return found;
}

ConditionOnSubspace ClassifyCondition(const HalfTurnSymmetry& s, const PointCondition& condition) {
  // A pin fixes a constant term its equation does not balance; where the
  // subspace has no such constant (an odd auxiliary), the pin is implied by
  // the auxiliary's equation and the definition's own parity.
  const int pinned = condition.pinned_variable;
  if (pinned >= 0 && pinned < static_cast<int>(s.sign.size()) && s.sign[pinned] < 0) return ConditionOnSubspace::kHolds;
  if (!s.reverses_time) return ConditionOnSubspace::kKept;
  for (int h : s.half_turn)
    if (h) return ConditionOnSubspace::kKept;
  // z_j(0) is free where z_j is even, z_j'(0) where it is odd; the rest are 0.
  const long n = static_cast<long>(s.sign.size());
  Eigen::VectorXd z(n), dz(n), gz(n), gdz(n);
  double value = 0;
  for (int draw = 1; draw <= 2; ++draw) {
    for (long j = 0; j < n; ++j) {
      z(j) = s.sign[j] > 0 ? 0.3 + 0.17 * double(j + 1) * draw : 0;
      dz(j) = s.sign[j] < 0 ? 0.21 + 0.13 * double(j + 1) * draw : 0;
    }
    gz.setZero();
    gdz.setZero();
    value = condition.function(z, dz, &gz, &gdz);
    for (long j = 0; j < n; ++j)
      if ((s.sign[j] > 0 && gz(j) != 0) || (s.sign[j] < 0 && gdz(j) != 0)) return ConditionOnSubspace::kKept;
  }
  return std::abs(value) <= 1e-12 ? ConditionOnSubspace::kHolds : ConditionOnSubspace::kViolated;
}

std::vector<HalfTurnSymmetry> SymmetriesOf(const HarmonicSolution& guess, const std::vector<HalfTurnSymmetry>& candidates,
                                           const std::vector<HalfTurnSymmetry>& already, double tolerance) {
  std::vector<HalfTurnSymmetry> held;
  const Eigen::MatrixXd& c = guess.coefficients();
  const HarmonicBasis& basis = guess.basis();
  const double scale = c.size() ? c.cwiseAbs().maxCoeff() : 0.0;
  if (!(scale > 0)) return held;  // rest has every symmetry: it says nothing of the solution
  auto size = [&](int j, int k) { return k == 0 ? std::abs(c(j, 0)) : std::hypot(c(j, 2 * k - 1), c(j, 2 * k)); };
  // The group generated so far (masks under xor): a composition adds nothing.
  std::vector<unsigned long> group = {0};
  auto extend = [&](const HalfTurnSymmetry& s) {
    const size_t n = group.size();
    for (size_t g = 0; g < n; ++g) group.push_back(group[g] ^ s.Mask());
  };
  for (const HalfTurnSymmetry& s : already) extend(s);
  for (const HalfTurnSymmetry& s : candidates) {
    if (static_cast<int>(s.sign.size()) != c.rows() || basis.num_bases() != static_cast<int>(s.half_turn.size()))
      continue;
    if (std::find(group.begin(), group.end(), s.Mask()) != group.end()) continue;
    double off = 0;
    for (int j = 0; j < c.rows(); ++j)
      for (int col = 0; col < c.cols(); ++col)
        if (!s.AllowsCoefficient(basis, col, s.sign[j]))
          off = std::max(off, std::abs(c(j, col)));
    if (off > tolerance * scale) continue;
    // A guess whose flipped variables are all zero (rest, where cos x = 1 is
    // not), or without any odd harmonic along a turned base (a constant, one
    // base excited alone), has such a symmetry trivially: no evidence.
    bool exercised = true, flips = false, flipped_moves = false;
    for (int j = 0; j < c.rows(); ++j)
      if (s.sign[j] < 0) {
        flips = true;
        for (int k = 0; k < basis.size() && !flipped_moves; ++k) flipped_moves = size(j, k) > tolerance * scale;
      }
    if (flips && !flipped_moves) continue;
    // A constant is even in t trivially.
    bool varies = false;
    for (int j = 0; j < c.rows() && s.reverses_time && !varies; ++j)
      for (int k = 1; k < basis.size() && !varies; ++k) varies = size(j, k) > tolerance * scale;
    if (s.reverses_time && !varies) continue;
    for (size_t b = 0; b < s.half_turn.size(); ++b) {
      if (!s.half_turn[b]) continue;
      bool odd = false;
      for (int k = 1; k < basis.size() && !odd; ++k)
        if (basis.harmonic(k)[b] % 2 != 0)
          for (int j = 0; j < c.rows() && !odd; ++j) odd = size(j, k) > tolerance * scale;
      exercised = exercised && odd;
    }
    if (!exercised) continue;
    held.push_back(s);
    extend(s);
  }
  return held;
}

}  // namespace rmhb
